//! `host display`: a local web server showing the field on the TV (the
//! TV's own browser, or a computer's on HDMI), its calibration sequence,
//! grey patches for measuring the display's gamma and marks for measuring
//! the panel's brightness gain (`docs/display.md`).
//!
//! It serves four things and nothing else: the page (`/`, plain HTML and
//! JavaScript built into the binary, so no internet is needed), the panel
//! image (`/field.png`, [`crate::panel_file`]), the calibration's white
//! screen (`/white.png`; both evened out for the panel's measured gain when
//! given one, [`crate::flat_field`]) and the page's settings
//! (`/settings.json`). It binds where it is told, loopback by default.

use crate::flat_field::MarkGrid;
use crate::panel_file;
use anyhow::{Context, Result};
use serde::Serialize;
use sim::base::gain_grid::GainGrid;
use sim::base::ranges;
use sim::fields::source::FieldSource;
use sim::scenario::arena::{ArenaSpec, SkirtShape};
use std::net::{SocketAddr, TcpListener};
use tiny_http::{Header, Method, Request, Response, Server};

/// The page, built in.
const PAGE: &str = include_str!("display.html");

/// The gap between the skirt's reach and a mark's ticks, mm.
const MARK_MARGIN_MM: f64 = 20.0;

/// The farthest the skirt reaches from a robot's centre, mm.
fn skirt_reach_mm(arena: &ArenaSpec) -> f64 {
    match arena.robot_shape {
        SkirtShape::Disc => arena.robot_radius_mm,
        SkirtShape::Wedge { tip_mm } => tip_mm.max(arena.robot_radius_mm),
    }
}

/// What to show and where to listen.
#[derive(Clone, Debug, PartialEq)]
pub struct DisplaySettings {
    /// The screen.
    pub arena: ArenaSpec,
    /// The field.
    pub field: FieldSource,
    /// Address to listen on (port 0: any free port).
    pub bind: SocketAddr,
    /// How long the calibration sequence holds white and black, ms.
    pub hold_ms: u32,
    /// The panel's measured gain, to even out what it shows.
    pub gain: Option<GainGrid>,
    /// The marks screen's grid.
    pub marks: MarkGrid,
}

/// The page's settings, as `/settings.json` gives them.
#[derive(Clone, Debug, PartialEq, Serialize)]
struct PageSettings {
    arena: String,
    field: String,
    panel: [u32; 2],
    hold_ms: u32,
    display_gamma: f64,
    /// Whether the images are evened out for a measured gain.
    flat: bool,
    screen_mm: [f64; 2],
    /// How far from a mark's centre its ticks start: clear of the skirt.
    mark_clear_mm: f64,
    /// The marks' centres, mm from the screen's top-left, row by row.
    marks: Vec<[f64; 2]>,
}

/// A display server, listening.
pub struct Display {
    server: Server,
    address: SocketAddr,
    png: Vec<u8>,
    white_png: Vec<u8>,
    settings_json: String,
}

impl Display {
    /// Renders the panel image and starts listening; errors name the
    /// field, the arena or the address.
    pub fn start(settings: &DisplaySettings) -> Result<Display> {
        let hold = settings.hold_ms;
        ranges::HOLD_S.check_as("hold_ms / 1000", f64::from(hold) / 1000.0)?;
        let arena = &settings.arena;
        arena
            .validate()
            .with_context(|| format!("arena {}", arena.name))?;
        let gain = settings.gain.as_ref();
        if let Some(grid) = gain {
            grid.validate().context("the panel's gain")?;
        }
        let image = panel_file::panel_image(arena, &settings.field, gain)?;
        let png = panel_file::encode_png(&image)?;
        let white_png = panel_file::encode_png(&sim::scenario::panel::white_image(arena, gain))?;
        let page = PageSettings {
            arena: arena.name.clone(),
            field: settings.field.to_string(),
            panel: arena.screen_px,
            hold_ms: hold,
            display_gamma: arena.display_gamma,
            flat: gain.is_some(),
            screen_mm: arena.screen_mm,
            mark_clear_mm: skirt_reach_mm(arena) + MARK_MARGIN_MM,
            marks: settings.marks.points_mm(arena),
        };
        let settings_json =
            serde_json::to_string(&page).context("cannot encode the page's settings")?;
        let listener = TcpListener::bind(settings.bind)
            .with_context(|| format!("cannot listen on {}", settings.bind))?;
        let address = listener
            .local_addr()
            .with_context(|| format!("cannot read the address of {}", settings.bind))?;
        let server = Server::from_listener(listener, None)
            .map_err(|e| anyhow::anyhow!("cannot serve on {address}: {e}"))?;
        Ok(Display {
            server,
            address,
            png,
            white_png,
            settings_json,
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

    /// Answers requests until the process ends; a client that goes away
    /// mid-answer is not an error.
    pub fn serve(&self) {
        for request in self.server.incoming_requests() {
            let _ = self.answer(request);
        }
    }

    fn answer(&self, request: Request) -> std::io::Result<()> {
        if !matches!(request.method(), Method::Get | Method::Head) {
            let text = format!("{} is not served: only GET and HEAD\n", request.method());
            return request.respond(Response::from_string(text).with_status_code(405));
        }
        let path = request
            .url()
            .split(['?', '#'])
            .next()
            .unwrap_or("")
            .to_string();
        let (body, kind) = match path.as_str() {
            "/" | "/index.html" => (PAGE.as_bytes().to_vec(), "text/html; charset=utf-8"),
            "/field.png" => (self.png.clone(), "image/png"),
            "/white.png" => (self.white_png.clone(), "image/png"),
            "/settings.json" => (self.settings_json.as_bytes().to_vec(), "application/json"),
            _ => {
                let text = format!(
                    "not found: {path} (this server has /, /field.png, /white.png and /settings.json)\n"
                );
                return request.respond(Response::from_string(text).with_status_code(404));
            }
        };
        let response = Response::from_data(body)
            .with_header(header("Content-Type", kind))
            .with_header(header("Cache-Control", "no-store"));
        request.respond(response)
    }
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("ASCII header")
}
