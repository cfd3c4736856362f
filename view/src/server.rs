//! The server: one simulation stepped by its own thread at the chosen
//! speed, its state published to every viewer's WebSocket, the page and
//! the field image over plain HTTP, controls and settings as POSTs.
//!
//! Requests: `GET /` (the page), `GET /field.png`, `GET /state.json` (the
//! current hello and frame, for scripts), `GET /stream` (WebSocket:
//! `hello`, then `frame`s), `POST /control?action=play|pause|step|reset`
//! (`&seed=N` with reset, `&steps=N` with step), `POST /control?speed=real|10x|max`,
//! `POST /settings?KEY=VALUE...` (the settings of [`crate::settings::keys`],
//! `speed` and `paused`), `POST /policy?name=NAME` (a policy blob as the
//! body). Refused settings answer 400 naming the key and change nothing.
//! The simulation's thread steps in slices of at most [`SLICE`], letting
//! waiting requests in between, so a long step request never keeps a
//! request waiting; a pause, play, reset or new settings cancel its steps.

use crate::http::{self, error_json, Connection, Connections, Request};
use crate::hub::Hub;
use crate::session::{self, Companion, Frame, Hello, History, Learning, Policy, Session};
use crate::settings::{self, valid_name, Allowed, ViewController, ViewSettings};
use serde::Serialize;
use sim::base::ranges;
use sim::control::policy_file;
use sim::scenario::sensor_setup::SelectedSensors;
use sim::simulation::Simulation;
use std::collections::BTreeMap;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use tungstenite::protocol::Role;
use tungstenite::{Message, Utf8Bytes, WebSocket};

/// The page, built in.
const PAGE: &str = include_str!("page.html");

/// Uploaded policies kept; the oldest goes first.
pub const MAX_UPLOADS: usize = 16;

/// Frames published a second, at most (a browser paints about 60).
pub const FRAMES_PER_SECOND: f64 = 60.0;

/// Steps a second in real time: the robot's 20 ms control period.
pub const REAL_TIME: f64 = 50.0;

/// Steps one `step` control may ask for.
pub const MAX_STEPS_PER_CONTROL: u64 = 1_000_000;

/// Longest the simulation's thread steps while holding the control lock
/// (but at least one step): it then lets waiting requests in, so every
/// request is answered while steps run.
pub const SLICE: Duration = Duration::from_millis(10);

/// Behind by more than this, paced stepping drops its backlog and goes on
/// from the present (a stall, a world too slow for the speed).
pub const CATCH_UP: Duration = Duration::from_millis(100);

/// How fast the simulation runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Speed {
    /// 50 steps a second.
    Real,
    /// 500 steps a second.
    Ten,
    /// As fast as it goes.
    Max,
}

impl Speed {
    fn rate(self) -> Option<f64> {
        match self {
            Speed::Real => Some(REAL_TIME),
            Speed::Ten => Some(10.0 * REAL_TIME),
            Speed::Max => None,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Speed::Real => "real",
            Speed::Ten => "10x",
            Speed::Max => "max",
        }
    }
}

/// A `speed=` parameter; errors name it.
fn speed_param(value: &str) -> Result<Speed, String> {
    value
        .parse()
        .map_err(|_| format!("speed={value}: expected real, 10x or max"))
}

impl std::str::FromStr for Speed {
    type Err = String;

    fn from_str(s: &str) -> Result<Speed, String> {
        match s {
            "real" | "1x" => Ok(Speed::Real),
            "10x" => Ok(Speed::Ten),
            "max" => Ok(Speed::Max),
            _ => Err(format!("speed {s:?}: expected real, 10x or max")),
        }
    }
}

/// How to start.
#[derive(Clone, Debug)]
pub struct ViewOptions {
    /// Where to listen (port 0: any free one).
    pub bind: SocketAddr,
    /// The first settings.
    pub settings: ViewSettings,
    /// The folder whose policy files a browser may choose.
    pub policies: Option<PathBuf>,
    /// Files a browser may name.
    pub allowed: Allowed,
    /// Start paused.
    pub paused: bool,
    /// The first speed.
    pub speed: Speed,
}

/// A view, listening, its simulation running.
pub struct View {
    address: SocketAddr,
    listener: TcpListener,
    shared: Arc<Shared>,
}

struct Shared {
    control: Mutex<Control>,
    /// Threads waiting for `control`: the simulation's thread lets them in
    /// between slices of steps.
    waiting: AtomicUsize,
    wake: Condvar,
    hub: Hub,
    connections: Arc<Connections>,
    policies: Option<PathBuf>,
    allowed: Allowed,
    /// Set when a [`Follower`] is dropped: the server ends.
    stopped: AtomicBool,
}

/// Where the frames come from.
#[allow(
    clippy::large_enum_variant,
    reason = "one per view, replaced only at a reset: boxing would buy nothing"
)]
enum Source {
    /// A simulation of the view's own, stepped by its thread.
    Own(Session),
    /// A world someone else steps ([`Follower`]): its last hello and frame,
    /// and whether that frame is published yet.
    Fed {
        hello: Hello,
        frame: Frame,
        published: bool,
    },
}

/// Refusal of the controls when the view follows a world stepped elsewhere.
const FOLLOWING: &str =
    "this view follows a world its owner steps (a Python environment): controls and settings are not available";

impl Source {
    fn own(&mut self) -> Result<&mut Session, String> {
        match self {
            Source::Own(session) => Ok(session),
            Source::Fed { .. } => Err(FOLLOWING.into()),
        }
    }

    fn hello(&self) -> Hello {
        match self {
            Source::Own(session) => session.hello(),
            Source::Fed { hello, .. } => hello.clone(),
        }
    }

    fn frame(&self) -> Frame {
        match self {
            Source::Own(session) => session.frame(),
            Source::Fed { frame, .. } => frame.clone(),
        }
    }

    /// One step of the view's own simulation.
    fn step(&mut self) {
        if let Source::Own(session) = self {
            session.step();
        }
    }

    fn steps(&self) -> u64 {
        match self {
            Source::Own(session) => session.simulation().totals().steps,
            Source::Fed { frame, .. } => frame.step,
        }
    }
}

struct Control {
    source: Source,
    /// The Eval plot's points since the last reset.
    history: History,
    /// Bumped at every reset: the field image's and hello's version.
    generation: u64,
    hello: Utf8Bytes,
    field_png: Arc<Vec<u8>>,
    paused: bool,
    speed: Speed,
    /// Single steps asked for and not yet run.
    pending: u64,
    /// Paced runs count steps from here.
    pace: Pace,
    last_publish: Option<Instant>,
    /// Steps a second, measured over the last second.
    meter: Vec<(Instant, u64)>,
    uploads: BTreeMap<String, (u64, Vec<u8>)>,
    uploads_made: u64,
}

/// Paced stepping at a rate: the steps due since an anchor, less those
/// run.
#[derive(Clone, Copy, Debug)]
struct Pace {
    from: Instant,
    done: u64,
}

impl Pace {
    /// Pacing from `now`, the first step due one period later.
    fn new(now: Instant) -> Pace {
        Pace { from: now, done: 0 }
    }

    /// Steps due at `now` at `rate` a second and not yet run. Behind by
    /// more than [`CATCH_UP`], the backlog is dropped: pacing goes on from
    /// `now`, one step due.
    fn due(&mut self, now: Instant, rate: f64) -> u64 {
        let due = (now.saturating_duration_since(self.from).as_secs_f64() * rate) as u64;
        let behind = due.saturating_sub(self.done);
        if behind as f64 > rate * CATCH_UP.as_secs_f64() {
            let period = Duration::from_secs_f64(1.0 / rate);
            *self = Pace::new(now.checked_sub(period).unwrap_or(now));
            return 1;
        }
        behind
    }

    /// `n` steps were run.
    fn ran(&mut self, n: u64) {
        self.done += n;
    }

    /// When the next step is due at `rate`.
    fn next(&self, rate: f64) -> Instant {
        self.from + Duration::from_secs_f64((self.done + 1) as f64 / rate)
    }
}

impl Control {
    /// Adds the step count now to the steps-a-second meter, which keeps
    /// the last second (and at least two readings).
    fn measure(&mut self) {
        let steps = self.source.steps();
        self.meter.push((Instant::now(), steps));
        let recent = Instant::now() - Duration::from_secs(1);
        let old = self.meter.iter().take_while(|m| m.0 < recent).count();
        let keep = self.meter.len().saturating_sub(2);
        self.meter.drain(..old.min(keep));
    }
}

/// A hello as browsers get it.
#[derive(Serialize)]
struct HelloMessage<'a> {
    t: &'static str,
    generation: u64,
    #[serde(flatten)]
    hello: &'a Hello,
    history: &'a [[f64; 3]],
    policies: Vec<String>,
    uploads: Vec<String>,
    arenas: Vec<String>,
}

/// A frame as browsers get it.
#[derive(Serialize)]
struct FrameMessage<'a> {
    t: &'static str,
    generation: u64,
    paused: bool,
    speed: &'static str,
    steps_per_second: f64,
    viewers: usize,
    #[serde(flatten)]
    frame: &'a Frame,
}

impl View {
    /// Builds the first simulation and starts listening and stepping;
    /// errors name the setting or the address.
    pub fn start(options: ViewOptions) -> Result<View, String> {
        let policy = policy_for(
            &options.settings,
            options.policies.as_deref(),
            &BTreeMap::new(),
        )?;
        let session = Session::build(options.settings, policy)?;
        let field_png = session.field_png()?;
        let view = View::listen(
            options.bind,
            Source::Own(session),
            field_png,
            options.policies,
            options.allowed,
            options.paused,
            options.speed,
        )?;
        let stepper = view.shared.clone();
        std::thread::Builder::new()
            .name("view-sim".into())
            .spawn(move || stepper.run())
            .map_err(|e| format!("cannot start the simulation's thread: {e}"))?;
        Ok(view)
    }

    /// Listens on `bind` (port 0: any free one) and serves frames of a world
    /// the caller steps: `sim` as it is now, then whatever the returned
    /// [`Follower`] is given after each step or reset. The page's controls
    /// and settings are refused. Serves from background threads until the
    /// follower is dropped.
    pub fn follow(bind: SocketAddr, sim: &Simulation<SelectedSensors>) -> Result<Follower, String> {
        View::follow_beside(bind, sim, None)
    }

    /// [`View::follow`], the page showing `companion` beside the world.
    pub fn follow_beside(
        bind: SocketAddr,
        sim: &Simulation<SelectedSensors>,
        companion: Option<Companion>,
    ) -> Result<Follower, String> {
        let source = Source::Fed {
            hello: Hello {
                companion: companion.clone(),
                ..Hello::of(sim, Vec::new())
            },
            frame: Frame::of(sim),
            published: false,
        };
        let view = View::listen(
            bind,
            source,
            session::field_png(sim)?,
            None,
            Allowed::default(),
            true,
            Speed::Real,
        )?;
        let shared = view.shared.clone();
        let address = view.address;
        let publisher = shared.clone();
        std::thread::Builder::new()
            .name("view-publish".into())
            .spawn(move || publisher.publish_fed())
            .map_err(|e| format!("cannot start the publishing thread: {e}"))?;
        let accept = std::thread::Builder::new()
            .name("view-accept".into())
            .spawn(move || view.serve())
            .map_err(|e| format!("cannot start the server's thread: {e}"))?;
        Ok(Follower {
            shared,
            address,
            accept: Some(accept),
            companion,
            caption: None,
        })
    }

    /// Listens on `bind` and sets up the state `source` starts with.
    fn listen(
        bind: SocketAddr,
        source: Source,
        field_png: Vec<u8>,
        policies: Option<PathBuf>,
        allowed: Allowed,
        paused: bool,
        speed: Speed,
    ) -> Result<View, String> {
        let listener = http::bind_listener(bind)?;
        let address = listener
            .local_addr()
            .map_err(|e| format!("cannot read the address of {bind}: {e}"))?;
        let shared = Arc::new(Shared {
            control: Mutex::new(Control {
                source,
                history: History::default(),
                generation: 0,
                hello: Utf8Bytes::from_static(""),
                field_png: Arc::new(field_png),
                paused,
                speed,
                pending: 0,
                pace: Pace::new(Instant::now()),
                last_publish: None,
                meter: Vec::new(),
                uploads: BTreeMap::new(),
                uploads_made: 0,
            }),
            waiting: AtomicUsize::new(0),
            wake: Condvar::new(),
            hub: Hub::default(),
            connections: Arc::new(Connections::new(address)),
            policies,
            allowed,
            stopped: AtomicBool::new(false),
        });
        {
            let mut c = shared.lock();
            let frame = c.source.frame();
            c.history.record(&frame);
            c.hello = shared.hello_message(&c);
        }
        Ok(View {
            address,
            listener,
            shared,
        })
    }

    /// Where it listens.
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.address)
    }

    /// Answers connections until the process ends, each in its own thread.
    pub fn serve(&self) {
        let shared = self.shared.clone();
        http::serve_connections(
            &self.listener,
            &self.shared.connections,
            &self.shared.stopped,
            move |connection| shared.connection(connection),
        );
    }

    /// Serves from a background thread (the caller goes on: a Python
    /// environment, a test).
    pub fn spawn(self) -> Result<SocketAddr, String> {
        let address = self.address;
        http::spawn_server(move || self.serve())?;
        Ok(address)
    }
}

/// The policy `settings` names: a file of the policy folder or an upload.
fn policy_for(
    settings: &ViewSettings,
    folder: Option<&Path>,
    uploads: &BTreeMap<String, (u64, Vec<u8>)>,
) -> Result<Option<Policy>, String> {
    match &settings.controller {
        ViewController::Orbital | ViewController::Random => Ok(None),
        ViewController::Policy(name) => {
            let folder = folder.ok_or("this server has no policy folder (--policies)")?;
            let path = folder.join(name);
            let blob = policy_file::read(&path).map_err(|e| e.to_string())?;
            Ok(Some(Policy { path, blob }))
        }
        ViewController::Upload(name) => {
            let (_, bytes) = uploads
                .get(name)
                .ok_or_else(|| format!("no uploaded policy is named {name:?}"))?;
            let path = PathBuf::from(format!("upload:{name}"));
            let blob = policy_file::decode(&path, bytes).map_err(|e| e.to_string())?;
            Ok(Some(Policy { path, blob }))
        }
    }
}

/// The policy files of `folder`, by name.
fn policy_names(folder: Option<&Path>) -> Vec<String> {
    let Some(entries) = folder.and_then(|f| std::fs::read_dir(f).ok()) else {
        return Vec::new();
    };
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".policy") && valid_name(n))
        .collect();
    names.sort();
    names
}

fn json<T: Serialize>(value: &T) -> Utf8Bytes {
    // our own types, of numbers and strings, always encode
    serde_json::to_string(value)
        .unwrap_or_else(|e| format!("{{\"t\":\"error\",\"error\":\"{e}\"}}"))
        .into()
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Control> {
        self.waiting.fetch_add(1, Ordering::SeqCst);
        // the control is consistent between statements: a panic in a step
        // leaves a world a reset replaces
        let c = self
            .control
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        self.waiting.fetch_sub(1, Ordering::SeqCst);
        c
    }

    /// Lets the threads waiting for the control lock have it (for at most
    /// a few milliseconds, so a flood of requests cannot stop the
    /// simulation), then takes it again.
    fn let_others_in<'a>(&'a self, c: MutexGuard<'a, Control>) -> MutexGuard<'a, Control> {
        drop(c);
        for _ in 0..50 {
            if self.waiting.load(Ordering::SeqCst) == 0 {
                break;
            }
            std::thread::sleep(Duration::from_micros(100));
        }
        self.lock()
    }

    fn hello_message(&self, c: &Control) -> Utf8Bytes {
        let mut arenas = vec!["".to_string(), "thesis".to_string()];
        arenas.extend(
            sim::scenario::arena::ArenaSpec::NAMES
                .split(", ")
                .map(String::from),
        );
        arenas.extend(
            self.allowed
                .arena_files
                .iter()
                .map(|p| p.display().to_string()),
        );
        json(&HelloMessage {
            t: "hello",
            generation: c.generation,
            hello: &c.source.hello(),
            history: c.history.points(),
            policies: policy_names(self.policies.as_deref()),
            uploads: c.uploads.keys().cloned().collect(),
            arenas,
        })
    }

    fn frame_message(&self, c: &Control) -> Utf8Bytes {
        self.frame_message_of(c, &c.source.frame())
    }

    fn frame_message_of(&self, c: &Control, frame: &Frame) -> Utf8Bytes {
        let rate = match (c.meter.first(), c.meter.last()) {
            (Some(a), Some(b)) if b.0 > a.0 => (b.1 - a.1) as f64 / (b.0 - a.0).as_secs_f64(),
            _ => 0.0,
        };
        json(&FrameMessage {
            t: "frame",
            generation: c.generation,
            paused: c.paused,
            speed: c.speed.name(),
            steps_per_second: (rate * 10.0).round() / 10.0,
            viewers: self.hub.viewers(),
            frame,
        })
    }

    fn publish(&self, c: &mut Control) {
        let frame = c.source.frame();
        c.history.record(&frame);
        c.last_publish = Some(Instant::now());
        let message = self.frame_message_of(c, &frame);
        self.hub.publish(&message);
    }

    /// Replaces the simulation (a reset, new settings; `png` its field
    /// image), cancels pending steps and tells every viewer.
    fn replace(&self, c: &mut Control, session: Session, png: Vec<u8>) {
        c.source = Source::Own(session);
        c.pending = 0;
        self.restart(c, png);
        self.publish(c);
    }

    /// A new generation: its field image, an empty plot, a hello to every viewer.
    fn restart(&self, c: &mut Control, png: Vec<u8>) {
        c.field_png = Arc::new(png);
        c.history = History::default();
        c.generation += 1;
        c.pace = Pace::new(Instant::now());
        c.meter.clear();
        c.hello = self.hello_message(c);
        self.hub.publish(&c.hello);
    }

    /// The publishing thread of a [`Follower`]: the newest frame it was
    /// given, at most [`FRAMES_PER_SECOND`] a second, and always the last.
    fn publish_fed(&self) {
        let frame_gap = Duration::from_secs_f64(1.0 / FRAMES_PER_SECOND);
        let mut c = self.lock();
        while !self.stopped.load(Ordering::SeqCst) {
            if let Source::Fed { published, .. } = &mut c.source {
                if !*published {
                    *published = true;
                    self.publish(&mut c);
                    drop(c);
                    std::thread::sleep(frame_gap);
                    c = self.lock();
                    continue;
                }
            }
            c = self
                .wake
                .wait(c)
                .unwrap_or_else(std::sync::PoisonError::into_inner);
        }
    }

    /// The simulation's thread: steps at the chosen speed, publishes. It
    /// holds the control lock for at most [`SLICE`] of steps at a time,
    /// then lets waiting requests in.
    fn run(&self) {
        let frame_gap = Duration::from_secs_f64(1.0 / FRAMES_PER_SECOND);
        let mut c = self.lock();
        loop {
            while c.paused && c.pending == 0 {
                c = self
                    .wake
                    .wait(c)
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                c.pace = Pace::new(Instant::now());
            }
            let now = Instant::now();
            let rate = c.speed.rate();
            let want = match (c.pending, rate) {
                (0, Some(rate)) => c.pace.due(now, rate),
                (0, None) => u64::MAX,
                (pending, _) => pending,
            };
            let mut ran = 0;
            while ran < want {
                c.source.step();
                ran += 1;
                if now.elapsed() >= SLICE {
                    break;
                }
            }
            let single = c.pending > 0 && c.pending == ran;
            if c.pending > 0 {
                c.pending -= ran;
            } else {
                c.pace.ran(ran);
            }
            if ran > 0 {
                c.measure();
            }
            let due = c.last_publish.is_none_or(|t| t.elapsed() >= frame_gap);
            if ran > 0 && (due || single) {
                self.publish(&mut c);
            }
            // wait for the next step or frame, or a control
            let wait = match (c.paused, c.pending, rate) {
                (_, p, _) if p > 0 => Duration::ZERO,
                (true, _, _) => Duration::ZERO,
                (false, _, Some(rate)) => c
                    .pace
                    .next(rate)
                    .saturating_duration_since(Instant::now())
                    .min(frame_gap),
                (false, _, None) => Duration::ZERO,
            };
            c = if wait.is_zero() {
                self.let_others_in(c)
            } else {
                self.wake
                    .wait_timeout(c, wait)
                    .unwrap_or_else(std::sync::PoisonError::into_inner)
                    .0
            };
        }
    }

    /// One connection: one request, or a WebSocket's life.
    fn connection(&self, mut connection: Connection) {
        let limit = ranges::POLICY_FILE.max as usize;
        let Some(request) = http::accept_request(&mut connection, limit) else {
            return;
        };
        if request.path == "/stream" && request.is_websocket() {
            return self.stream(connection, &request);
        }
        let (status, kind, body) = self.answer(&request);
        http::reply(&mut connection.stream, &request, status, kind, &body);
    }

    fn answer(&self, request: &Request) -> (u16, &'static str, Vec<u8>) {
        const JSON: &str = "application/json";
        let method = request.method.as_str();
        let get = method == "GET" || method == "HEAD";
        match (request.path.as_str(), get, method == "POST") {
            ("/" | "/index.html", true, _) => {
                (200, "text/html; charset=utf-8", PAGE.as_bytes().to_vec())
            }
            ("/field.png", true, _) => (200, "image/png", self.lock().field_png.to_vec()),
            ("/state.json", true, _) => {
                let c = self.lock();
                let body = format!("{{\"hello\":{},\"frame\":{}}}", c.hello, self.frame_message(&c));
                (200, JSON, body.into_bytes())
            }
            ("/control", _, true) => match self.control(&request.query) {
                Ok(()) => (200, JSON, b"{\"ok\":true}".to_vec()),
                Err(e) => (400, JSON, error_json(&e)),
            },
            ("/settings", _, true) => match self.settings(&request.query) {
                Ok(()) => (200, JSON, b"{\"ok\":true}".to_vec()),
                Err(e) => (400, JSON, error_json(&e)),
            },
            ("/policy", _, true) => match self.upload(&request.query, &request.body) {
                Ok(name) => (200, JSON, serde_json::json!({ "ok": true, "name": name }).to_string().into_bytes()),
                Err(e) => (400, JSON, error_json(&e)),
            },
            ("/" | "/index.html" | "/field.png" | "/state.json" | "/stream", _, _)
            | ("/control" | "/settings" | "/policy", _, _) => (
                405,
                JSON,
                error_json(&format!("{method} is not served at {}", request.path)),
            ),
            (path, _, _) => (
                404,
                JSON,
                error_json(&format!(
                    "not found: {path} (this server has /, /field.png, /state.json, /stream, /control, /settings and /policy)"
                )),
            ),
        }
    }

    fn control(&self, query: &str) -> Result<(), String> {
        let pairs = settings::query_pairs(query);
        if let Some((key, _)) = pairs
            .iter()
            .find(|(k, _)| !["action", "speed", "steps", "seed"].contains(&k.as_str()))
        {
            return Err(format!(
                "unknown control {key:?}: expected action, speed, steps or seed"
            ));
        }
        let get = |key: &str| {
            pairs
                .iter()
                .find(|(k, _)| k == key)
                .map(|(_, v)| v.as_str())
        };
        let action = get("action");
        let speed = get("speed").map(speed_param).transpose()?;
        for (key, with) in [("steps", "step"), ("seed", "reset")] {
            if get(key).is_some() && action != Some(with) {
                return Err(format!("{key}= goes with action={with}"));
            }
        }
        let mut rebuilt = None;
        match action {
            None if speed.is_some() => {}
            Some("play" | "pause" | "step") => {}
            Some("reset") => {
                let seed = get("seed")
                    .map(|seed| {
                        seed.parse().map_err(|_| {
                            format!("seed={seed}: not a whole number from 0 to 2^64 - 1")
                        })
                    })
                    .transpose()?;
                rebuilt = Some(self.rebuild(|now| {
                    let mut next = now.clone();
                    next.world.seed = seed.unwrap_or(now.world.seed);
                    Ok(next)
                })?);
            }
            Some(other) => {
                return Err(format!(
                    "action={other}: expected play, pause, step or reset"
                ))
            }
            None => return Err("no action= or speed= given".into()),
        }
        let steps = match get("steps") {
            None => 1,
            Some(s) => {
                let n = s
                    .parse::<u64>()
                    .map_err(|_| format!("steps={s}: not a whole number"))?;
                ranges::RUN_STEPS
                    .check_count("steps", n)
                    .map_err(|e| e.to_string())?;
                n.min(MAX_STEPS_PER_CONTROL)
            }
        };
        let mut c = self.lock();
        c.source.own()?;
        if let Some(speed) = speed {
            c.speed = speed;
            c.pace = Pace::new(Instant::now());
        }
        match action {
            Some("play") => {
                c.paused = false;
                c.pending = 0;
                c.pace = Pace::new(Instant::now());
            }
            Some("pause") => {
                c.paused = true;
                c.pending = 0;
                self.publish(&mut c);
            }
            Some("step") => {
                c.paused = true;
                c.pending = c.pending.saturating_add(steps).min(MAX_STEPS_PER_CONTROL);
            }
            _ => {}
        }
        if let Some((session, png)) = rebuilt {
            self.replace(&mut c, session, png);
        }
        self.wake.notify_all();
        Ok(())
    }

    /// A new session of the settings `change` makes of the running ones,
    /// and its field image, built outside the control lock (a large world
    /// takes a while) so requests and steps go on meanwhile.
    fn rebuild(
        &self,
        change: impl FnOnce(&ViewSettings) -> Result<ViewSettings, String>,
    ) -> Result<(Session, Vec<u8>), String> {
        let (next, policy) = {
            let mut c = self.lock();
            let next = change(c.source.own()?.settings())?;
            let policy = policy_for(&next, self.policies.as_deref(), &c.uploads)?;
            (next, policy)
        };
        let session = Session::build(next, policy)?;
        let png = session.field_png()?;
        Ok((session, png))
    }

    /// New settings: the world's (a new simulation, pending steps
    /// cancelled) when any of [`settings::keys`] is given, and `speed` and
    /// `paused`; refused as a whole, naming the key, if any is bad.
    fn settings(&self, query: &str) -> Result<(), String> {
        let pairs = settings::query_pairs(query);
        let mut speed = None;
        let mut paused = None;
        for (key, value) in &pairs {
            match key.as_str() {
                "speed" => speed = Some(speed_param(value)?),
                "paused" => {
                    paused = Some(match value.as_str() {
                        "true" => true,
                        "false" => false,
                        _ => return Err(format!("paused={value}: expected true or false")),
                    })
                }
                _ => {}
            }
        }
        let world = pairs.is_empty() || pairs.iter().any(|(k, _)| k != "speed" && k != "paused");
        let rebuilt = if world {
            Some(self.rebuild(|now| now.with_query(query, &self.allowed, &["speed", "paused"]))?)
        } else {
            None
        };
        let mut c = self.lock();
        c.source.own()?;
        if let Some((session, png)) = rebuilt {
            self.replace(&mut c, session, png);
        }
        if let Some(speed) = speed {
            c.speed = speed;
        }
        if let Some(paused) = paused {
            c.paused = paused;
            c.pending = 0;
        }
        c.pace = Pace::new(Instant::now());
        self.publish(&mut c);
        self.wake.notify_all();
        Ok(())
    }

    fn upload(&self, query: &str, body: &[u8]) -> Result<String, String> {
        self.lock().source.own()?;
        let pairs = settings::query_pairs(query);
        let name = pairs
            .iter()
            .find(|(k, _)| k == "name")
            .map(|(_, v)| v.clone())
            .ok_or("no name= given for the upload")?;
        if !valid_name(&name) {
            return Err(format!(
                "name={name}: upload names are letters, digits, '.', '-' and '_'"
            ));
        }
        policy_file::decode(Path::new(&name), body).map_err(|e| e.to_string())?;
        let mut c = self.lock();
        c.uploads_made += 1;
        let order = c.uploads_made;
        c.uploads.insert(name.clone(), (order, body.to_vec()));
        if c.uploads.len() > MAX_UPLOADS {
            let oldest = c
                .uploads
                .iter()
                .min_by_key(|(_, (k, _))| *k)
                .map(|(n, _)| n.clone());
            if let Some(oldest) = oldest {
                c.uploads.remove(&oldest);
            }
        }
        c.hello = self.hello_message(&c);
        self.hub.publish(&c.hello);
        Ok(name)
    }

    /// A viewer's WebSocket: the hello and then every frame, until the
    /// viewer goes away or is dropped for not keeping up.
    fn stream(&self, connection: Connection, request: &Request) {
        // `connection` stays open, and counted, for the viewer's life
        let Ok(mut stream) = connection.stream.try_clone() else {
            return;
        };
        if !http::accept_websocket(&mut stream, request) {
            return;
        }
        let queue = {
            // under the lock, so no frame is published between these and the queue
            let c = self.lock();
            self.hub
                .subscribe(&[c.hello.clone(), self.frame_message(&c)])
        };
        let mut socket = WebSocket::from_raw_socket(stream, Role::Server, None);
        loop {
            let message = match queue.recv_timeout(Duration::from_secs(5)) {
                Ok(text) => Message::Text(text),
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => Message::Ping(Vec::new().into()),
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
            };
            if socket.send(message).is_err() {
                return;
            }
        }
        let _ = socket.close(None);
        let _ = socket.flush();
    }
}

/// The server of a world the caller steps ([`View::follow`]): give it the
/// world after each step ([`Follower::step`]) and reset
/// ([`Follower::reset`]); dropping it stops the server.
pub struct Follower {
    shared: Arc<Shared>,
    address: SocketAddr,
    accept: Option<JoinHandle<()>>,
    companion: Option<Companion>,
    caption: Option<String>,
}

impl Follower {
    /// Where it listens.
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://{}/", self.address)
    }

    /// `sim` after a step: its frame, published by the server's thread (at
    /// most [`FRAMES_PER_SECOND`] a second; the newest is always sent).
    pub fn step(&self, sim: &Simulation<SelectedSensors>) {
        self.show(Frame::of(sim));
    }

    /// [`Follower::step`] for a world a learner learns in: `learning` is
    /// its progress, shown with the frame.
    pub fn step_learning(&self, sim: &Simulation<SelectedSensors>, learning: Learning) {
        self.show(Frame {
            learning: Some(learning),
            ..Frame::of(sim)
        });
    }

    /// `sim`, a world other than the one followed so far (another trial),
    /// under `caption`: [`Follower::reset`] with the caption shown over the
    /// page's panel from now on.
    pub fn switch(
        &mut self,
        sim: &Simulation<SelectedSensors>,
        caption: String,
    ) -> Result<(), String> {
        self.caption = Some(caption);
        self.reset(sim)
    }

    /// Viewers connected now.
    pub fn viewers(&self) -> usize {
        self.shared.hub.viewers()
    }

    fn show(&self, frame: Frame) {
        let mut c = self.shared.lock();
        if let Source::Fed {
            frame: last,
            published,
            ..
        } = &mut c.source
        {
            *last = frame;
            *published = false;
        }
        c.measure();
        self.shared.wake.notify_all();
    }

    /// `sim` after a reset (a new episode, a new seed): a new hello and
    /// field image, then its frame.
    pub fn reset(&self, sim: &Simulation<SelectedSensors>) -> Result<(), String> {
        let png = session::field_png(sim)?;
        let mut c = self.shared.lock();
        c.source = Source::Fed {
            hello: Hello {
                companion: self.companion.clone(),
                caption: self.caption.clone(),
                ..Hello::of(sim, Vec::new())
            },
            frame: Frame::of(sim),
            published: false,
        };
        self.shared.restart(&mut c, png);
        self.shared.wake.notify_all();
        Ok(())
    }
}

impl Drop for Follower {
    fn drop(&mut self) {
        self.shared.stopped.store(true, Ordering::SeqCst);
        self.shared.wake.notify_all();
        // wake the accepting thread, which then sees `stopped` and ends,
        // closing the listener; viewers' queues end with the hub's list
        let _ = TcpStream::connect_timeout(&self.address, Duration::from_secs(1));
        if let Some(accept) = self.accept.take() {
            let _ = accept.join();
        }
        self.shared.hub.close();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Steps `pace` runs at `rate`, asked every 5 ms from `from` to `to`
    /// (seconds after `start`).
    fn run(pace: &mut Pace, start: Instant, from: f64, to: f64) -> u64 {
        let mut ran = 0;
        let mut t = from;
        while t < to {
            let n = pace.due(start + Duration::from_secs_f64(t), REAL_TIME);
            pace.ran(n);
            ran += n;
            t += 0.005;
        }
        ran
    }

    #[test]
    fn after_a_stall_paced_steps_go_on_from_the_present() {
        let start = Instant::now();
        let mut pace = Pace::new(start);
        let before = run(&mut pace, start, 0.0, 30.0);
        assert!(before.abs_diff(1500) <= 2, "{before} steps in 30 s");
        // stalled from 30 s to 35 s (SIGSTOP, a loaded machine): the second
        // after it runs at the rate, neither frozen nor catching up
        let after = run(&mut pace, start, 35.0, 36.0);
        assert!(
            (45..=55).contains(&after),
            "{after} steps in the second after a stall"
        );
    }
}
