//! `host monitor`: records a robot's serial log into a recorded-log file
//! with host timestamps, keeps a live status of what it receives, and
//! survives the port going away (unplugged adapter, radio out of range):
//! it reports, waits and reopens the port.
//!
//! The loop is a library function driven by a [`PortOpener`] and a stop
//! flag, so tests run it over a pseudo-terminal or an in-memory stream and
//! stop it after a number of frames instead of racing a timer.

use super::frame_splitter::{ChunkEnd, FrameSplitter};
use super::log_file::{host_time_us, LogWriter};
use anyhow::{Context, Result};
use shared::{Faults, LogFrame, RunMode};
use std::fmt;
use std::io::{ErrorKind, IsTerminal, Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// The robot's serial settings: 115200 8N1.
pub const DEFAULT_BAUD: u32 = 115_200;
/// How long one read waits for data before the loop checks the stop flag.
const READ_TIMEOUT: Duration = Duration::from_millis(100);

/// Opens the byte stream to monitor (again, after it was lost).
pub trait PortOpener {
    /// Opens the stream; an error means "not there (yet)".
    fn open(&mut self) -> Result<Box<dyn Read + Send>>;
}

/// A serial port by path, e.g. `/dev/ttyUSB0` (8N1, no flow control).
pub struct SerialOpener {
    /// Port path or name.
    pub port: String,
    /// Baud rate.
    pub baud: u32,
}

/// Why a port can never be monitored, however long the monitor waits (a
/// path that is not a serial device, a baud rate that resets the robot):
/// [`run`] gives up with it instead of retrying.
#[derive(Debug)]
pub struct Unusable(pub String);

impl fmt::Display for Unusable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Unusable {}

impl SerialOpener {
    /// Fails with [`Unusable`] when the port can never be monitored: the
    /// 1200-baud touch, or a path that exists and is no serial device (a
    /// regular file, a directory, `/dev/zero`). A path that does not exist
    /// passes: the adapter may not be plugged in yet.
    pub fn check(&self) -> Result<(), Unusable> {
        self.check_baud()?;
        match not_a_serial_device(Path::new(&self.port)) {
            Some(what) => Err(Unusable(format!(
                "port {} is {what}, not a serial device: give the robot's port (host monitor --list lists them)",
                self.port
            ))),
            None => Ok(()),
        }
    }

    fn check_baud(&self) -> Result<(), Unusable> {
        if self.baud == shared::identity::USB_TOUCH_BAUD {
            return Err(Unusable(format!(
                "{} baud on a robot's USB port is the touch that resets it into its bootloader when the port \
                 closes: monitor at another rate (any rate works on USB)",
                self.baud
            )));
        }
        Ok(())
    }
}

/// What the file at `path` is, if it exists and is no terminal (serial
/// ports are terminals): "a regular file", "a directory", "a character
/// device that is not a terminal".
#[cfg(unix)]
fn not_a_serial_device(path: &Path) -> Option<&'static str> {
    use std::io::IsTerminal;
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    let kind = std::fs::metadata(path).ok()?.file_type();
    if kind.is_file() {
        Some("a regular file")
    } else if kind.is_dir() {
        Some("a directory")
    } else if kind.is_char_device() {
        // without blocking on a modem line, without becoming its controller
        let file = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
            .open(path)
            .ok()?;
        (!file.is_terminal()).then_some("a character device that is not a terminal")
    } else {
        Some("neither a file nor a device (a pipe or a socket)")
    }
}

/// Elsewhere the serial library's error says what is wrong.
#[cfg(not(unix))]
fn not_a_serial_device(_path: &Path) -> Option<&'static str> {
    None
}

impl PortOpener for SerialOpener {
    fn open(&mut self) -> Result<Box<dyn Read + Send>> {
        self.check_baud()?;
        let port = serialport::new(&self.port, self.baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(READ_TIMEOUT)
            .open();
        match port {
            Ok(port) => Ok(Box::new(port)),
            // the device is there and is no port: waiting will not help
            Err(e) => Err(match self.check() {
                Err(unusable) => anyhow::Error::new(unusable),
                Ok(()) => anyhow::Error::new(e).context(format!(
                    "cannot open serial port {} at {} baud",
                    self.port, self.baud
                )),
            }),
        }
    }
}

/// The serial ports the system reports, one line each (name and, for USB
/// adapters, vendor, product and serial number).
pub fn list_ports() -> Result<Vec<String>> {
    let ports = serialport::available_ports().context("cannot list serial ports")?;
    Ok(ports
        .into_iter()
        .map(|p| match p.port_type {
            serialport::SerialPortType::UsbPort(u) => format!(
                "{}  USB {:04x}:{:04x} {} {} {}",
                p.port_name,
                u.vid,
                u.pid,
                u.manufacturer.unwrap_or_default(),
                u.product.unwrap_or_default(),
                u.serial_number
                    .map(|s| format!("serial {s}"))
                    .unwrap_or_default()
            )
            .trim_end()
            .to_string(),
            serialport::SerialPortType::BluetoothPort => format!("{}  Bluetooth", p.port_name),
            serialport::SerialPortType::PciPort => format!("{}  PCI", p.port_name),
            serialport::SerialPortType::Unknown => p.port_name,
        })
        .collect())
}

/// When the loop stops by itself, and how it retries.
#[derive(Clone, Copy, Debug)]
pub struct MonitorOptions {
    /// Stop after recording this many frames (valid or not).
    pub max_frames: Option<u64>,
    /// Pause between attempts to reopen a lost port.
    pub reopen_interval: Duration,
}

impl Default for MonitorOptions {
    fn default() -> MonitorOptions {
        MonitorOptions {
            max_frames: None,
            reopen_interval: Duration::from_millis(500),
        }
    }
}

/// What the monitor has received so far: the live status line.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LiveStatus {
    /// Frames recorded.
    pub frames: u64,
    /// Recorded frames that do not decode (corrupt, another format version).
    pub decode_errors: u64,
    /// Bytes dropped when (re)connecting (the partial frame the robot was
    /// sending when the monitor started listening) and runs longer than
    /// any frame ([`super::frame_splitter::MAX_CHUNK`]: noise, not recorded).
    pub skipped_bytes: u64,
    /// Decoded frames with any fault flag.
    pub fault_frames: u64,
    /// The last decoded frame's mode, tick and faults.
    pub last: Option<(RunMode, u32, Faults)>,
    /// Decoded frames per action, over frames where the policy drove.
    pub actions: [u64; 4],
    /// Times the port was lost.
    pub disconnects: u64,
}

impl LiveStatus {
    fn record(&mut self, decoded: Result<&LogFrame, ()>) {
        self.frames += 1;
        match decoded {
            Err(()) => self.decode_errors += 1,
            Ok(f) => {
                if !f.faults.is_empty() {
                    self.fault_frames += 1;
                }
                if f.policy_drove() {
                    if let Some(n) = self.actions.get_mut(f.action.index()) {
                        *n += 1;
                    }
                }
                self.last = Some((f.mode, f.tick, f.faults));
            }
        }
    }
}

impl fmt::Display for LiveStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "frames {} | decode errors {} | fault frames {}",
            self.frames, self.decode_errors, self.fault_frames
        )?;
        if let Some((mode, tick, faults)) = self.last {
            write!(f, " | tick {tick} {mode:?}")?;
            for (flag, name) in Faults::NAMED {
                if faults.contains(flag) {
                    write!(f, ", {name}")?;
                }
            }
        }
        let driven: u64 = self.actions.iter().sum();
        // None until the policy has driven at least once.
        let shares: Option<Vec<u64>> = self
            .actions
            .iter()
            .map(|n| (n * 100).checked_div(driven))
            .collect();
        if let Some(shares) = shares {
            f.write_str(" | actions")?;
            for (a, pct) in shares.iter().enumerate() {
                write!(f, " {a}:{pct}%")?;
            }
        }
        if self.disconnects > 0 {
            write!(f, " | disconnects {}", self.disconnects)?;
        }
        if self.skipped_bytes > 0 {
            write!(
                f,
                " | skipped {} bytes of partial frames and noise",
                self.skipped_bytes
            )?;
        }
        Ok(())
    }
}

/// What happened, for the caller to show.
#[derive(Debug)]
pub enum MonitorEvent<'a> {
    /// The port is open and being read.
    Connected,
    /// A frame was recorded.
    Frame(&'a LiveStatus),
    /// The port could not be opened; the monitor retries.
    OpenFailed(&'a anyhow::Error),
    /// The open port failed (unplugged); the monitor reopens it.
    Lost(&'a std::io::Error),
}

/// Reads frames from the port until `stop` is set or `options.max_frames`
/// are recorded, appending each to `log` as received; reopens the port
/// whenever it is lost. Returns the final status. Fails when the log file
/// cannot be written or the port can never be monitored ([`Unusable`]).
pub fn run(
    opener: &mut dyn PortOpener,
    log: &mut LogWriter,
    options: &MonitorOptions,
    stop: &AtomicBool,
    observer: &mut dyn FnMut(MonitorEvent<'_>),
) -> Result<LiveStatus> {
    let mut status = LiveStatus::default();
    let done = |status: &LiveStatus| options.max_frames.is_some_and(|max| status.frames >= max);
    let mut buf = [0u8; 512];
    while !stop.load(Ordering::SeqCst) && !done(&status) {
        let mut port = match opener.open() {
            Ok(port) => port,
            Err(e) if e.is::<Unusable>() => return Err(e),
            Err(e) => {
                observer(MonitorEvent::OpenFailed(&e));
                pause(options.reopen_interval, stop);
                continue;
            }
        };
        observer(MonitorEvent::Connected);
        // Bytes before the first delimiter belong to a frame that started
        // before we listened: dropped unless they happen to be a whole frame.
        let mut splitter = FrameSplitter::new();
        let mut synced = false;
        while !stop.load(Ordering::SeqCst) && !done(&status) {
            let n = match port.read(&mut buf) {
                Ok(0) => {
                    lost(
                        &mut status,
                        &std::io::Error::from(ErrorKind::UnexpectedEof),
                        observer,
                    );
                    break;
                }
                Ok(n) => n,
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::TimedOut | ErrorKind::WouldBlock | ErrorKind::Interrupted
                    ) =>
                {
                    continue
                }
                Err(e) => {
                    lost(&mut status, &e, observer);
                    break;
                }
            };
            for chunk in splitter.push(&buf[..n]) {
                if chunk.end == ChunkEnd::Cut {
                    // longer than any frame: noise, neither recorded nor a frame
                    status.skipped_bytes += chunk.bytes.len() as u64;
                    continue;
                }
                let decoded = LogFrame::decode(&chunk.bytes);
                if !synced && decoded.is_err() {
                    status.skipped_bytes += chunk.bytes.len() as u64;
                    synced = true;
                    continue;
                }
                synced = true;
                if done(&status) {
                    break;
                }
                log.append(host_time_us(), &chunk.bytes)?;
                status.record(decoded.as_ref().map_err(|_| ()));
                observer(MonitorEvent::Frame(&status));
            }
        }
        if done(&status) || stop.load(Ordering::SeqCst) {
            break;
        }
        splitter.discard_partial();
        pause(options.reopen_interval, stop);
    }
    log.sync()?;
    Ok(status)
}

fn lost(status: &mut LiveStatus, e: &std::io::Error, observer: &mut dyn FnMut(MonitorEvent<'_>)) {
    status.disconnects += 1;
    observer(MonitorEvent::Lost(e));
}

/// Sleeps for `total`, in short steps so that `stop` ends it early.
fn pause(total: Duration, stop: &AtomicBool) {
    let start = Instant::now();
    while !stop.load(Ordering::SeqCst) && start.elapsed() < total {
        std::thread::sleep((total - start.elapsed()).min(Duration::from_millis(50)));
    }
}

/// Shows [`MonitorEvent`]s on a terminal: connection changes on their own
/// lines, the status on one line rewritten in place (at most 5 times a
/// second; on a non-terminal, one line a second).
pub struct StatusPrinter<W: Write> {
    out: W,
    port: String,
    terminal: bool,
    last: Option<Instant>,
    failing: bool,
}

impl<W: Write + IsTerminal> StatusPrinter<W> {
    /// A printer for the port `port`, writing to `out`.
    pub fn new(out: W, port: &str) -> StatusPrinter<W> {
        let terminal = out.is_terminal();
        StatusPrinter {
            out,
            port: port.to_string(),
            terminal,
            last: None,
            failing: false,
        }
    }
}

impl<W: Write> StatusPrinter<W> {
    /// Shows one event. Output errors are ignored: the recording matters
    /// more than the display.
    pub fn show(&mut self, event: &MonitorEvent<'_>) {
        let line_start = if self.terminal { "\r\x1b[K" } else { "" };
        let port = &self.port;
        let _ = match event {
            MonitorEvent::Connected => {
                self.failing = false;
                writeln!(self.out, "{line_start}monitor: reading {port}")
            }
            MonitorEvent::OpenFailed(e) if !self.failing => {
                self.failing = true;
                writeln!(
                    self.out,
                    "{line_start}monitor: {e:#}; retrying until it appears (Ctrl-C ends)"
                )
            }
            MonitorEvent::OpenFailed(_) => Ok(()),
            MonitorEvent::Lost(e) => {
                writeln!(self.out, "{line_start}monitor: lost {port} ({e}); waiting for it to come back (Ctrl-C ends)")
            }
            MonitorEvent::Frame(status) => {
                let every = if self.terminal {
                    Duration::from_millis(200)
                } else {
                    Duration::from_secs(1)
                };
                if self.last.is_some_and(|t| t.elapsed() < every) {
                    return;
                }
                self.last = Some(Instant::now());
                if self.terminal {
                    write!(self.out, "{line_start}{status}")
                } else {
                    writeln!(self.out, "{status}")
                }
            }
        };
        let _ = self.out.flush();
    }

    /// Ends the status line and prints the final status.
    pub fn finish(&mut self, status: &LiveStatus) {
        let line_start = if self.terminal { "\r\x1b[K" } else { "" };
        let _ = writeln!(self.out, "{line_start}monitor: done: {status}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::robot::frame_splitter::MAX_CHUNK;
    use crate::robot::log_file;
    use shared::{ActionId, LogFrame};
    use std::collections::VecDeque;
    use std::io::Cursor;

    #[test]
    fn monitoring_at_1200_baud_is_refused_since_closing_would_reset_the_robot() {
        let mut opener = SerialOpener {
            port: "/dev/ttyACM0".to_string(),
            baud: shared::identity::USB_TOUCH_BAUD,
        };
        let e = opener.open().err().unwrap().to_string();
        assert!(e.contains("resets it into its bootloader"), "{e}");
    }

    fn frame(tick: u32, action: u8) -> Vec<u8> {
        let f = LogFrame {
            tick,
            mode: RunMode::Driving,
            action: ActionId(action),
            ..LogFrame::default()
        };
        let mut buf = [0u8; LogFrame::MAX_ENCODED_LEN];
        let n = f.encode(&mut buf);
        buf[..n].to_vec()
    }

    /// Streams that each end with an error (an unplugged port); opening
    /// fails once between two streams.
    struct Unplugging {
        streams: VecDeque<Vec<u8>>,
        fail_next: bool,
        opens: usize,
    }

    struct ThenFail(Cursor<Vec<u8>>);

    impl Read for ThenFail {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            match self.0.read(buf)? {
                0 => Err(std::io::Error::other("device disconnected")),
                n => Ok(n),
            }
        }
    }

    impl PortOpener for Unplugging {
        fn open(&mut self) -> Result<Box<dyn Read + Send>> {
            if std::mem::take(&mut self.fail_next) {
                anyhow::bail!("no such port");
            }
            self.fail_next = true;
            self.opens += 1;
            let s = self
                .streams
                .pop_front()
                .ok_or_else(|| anyhow::anyhow!("no such port"))?;
            Ok(Box::new(ThenFail(Cursor::new(s))))
        }
    }

    /// Monitors `streams` (each ending in an unplugging) into a new log
    /// until `max_frames` are recorded; returns the status, the log read
    /// back and how often the port was opened.
    fn monitor(
        streams: Vec<Vec<u8>>,
        max_frames: u64,
        observer: &mut dyn FnMut(MonitorEvent<'_>),
    ) -> (LiveStatus, log_file::Recording, usize) {
        let mut opener = Unplugging {
            streams: VecDeque::from(streams),
            fail_next: false,
            opens: 0,
        };
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.log");
        let mut log = LogWriter::create(&path, false).unwrap();
        let options = MonitorOptions {
            max_frames: Some(max_frames),
            reopen_interval: Duration::ZERO,
        };
        let stop = AtomicBool::new(false);
        let status = run(&mut opener, &mut log, &options, &stop, observer).unwrap();
        (status, log_file::read(&path).unwrap(), opener.opens)
    }

    #[test]
    fn records_across_unplugging_and_drops_only_the_partial_first_frame() {
        let first: Vec<u8> = [
            &frame(1, 0)[3..],
            &frame(2, 1),
            &frame(3, 1),
            &[0x55, 0x66, 0][..],
        ]
        .concat();
        let second: Vec<u8> = [
            &frame(7, 0)[..5],
            &[0][..],
            &frame(8, 2),
            &frame(9, 3),
            &frame(10, 3)[..4],
        ]
        .concat();
        let mut events = Vec::new();
        let (status, rec, opens) = monitor(vec![first, second], 5, &mut |e| {
            events.push(match e {
                MonitorEvent::Connected => "connected",
                MonitorEvent::Frame(_) => "frame",
                MonitorEvent::OpenFailed(_) => "open failed",
                MonitorEvent::Lost(_) => "lost",
            })
        });
        assert_eq!(opens, 2);
        assert_eq!(
            events,
            [
                "connected",
                "frame",
                "frame",
                "frame",
                "lost",
                "open failed",
                "connected",
                "frame",
                "frame"
            ]
        );
        // Recorded: ticks 2, 3, the garbage chunk (a decode error), 8, 9; the
        // partial first chunk of each connection is skipped, and the frame
        // cut by the unplugging never completes.
        assert_eq!(
            (status.frames, status.decode_errors, status.disconnects),
            (5, 1, 1)
        );
        assert_eq!(status.skipped_bytes, (frame(1, 0).len() - 4 + 5) as u64);
        assert_eq!(status.actions, [0, 2, 1, 1]);
        let ticks: Vec<Option<u32>> = rec
            .entries
            .iter()
            .map(|e| {
                LogFrame::decode(e.frame.as_ref().unwrap())
                    .ok()
                    .map(|f| f.tick)
            })
            .collect();
        assert_eq!(ticks, [Some(2), Some(3), None, Some(8), Some(9)]);
        assert!(rec
            .entries
            .iter()
            .all(|e| e.host_time_us.is_some_and(|t| t > 0)));
        let line = status.to_string();
        assert!(
            line.contains("frames 5 | decode errors 1")
                && line.contains("actions 0:0% 1:50% 2:25% 3:25%"),
            "{line}"
        );
    }

    #[test]
    fn noise_longer_than_any_frame_is_neither_recorded_nor_counted_as_frames() {
        // 1,040 bytes of noise (a wrong baud rate) between two frames
        let stream: Vec<u8> = [
            &frame(1, 0)[..],
            &frame(2, 1),
            &vec![0x55; MAX_CHUNK + 16],
            &[0],
            &frame(3, 1),
            &frame(4, 2),
        ]
        .concat();
        let (status, rec, _) = monitor(vec![stream], 3, &mut |_| {});
        // frame 1 is the first chunk, kept since it decodes; --frames 3
        // ends after frames 2 and 3, the noise not among them
        assert_eq!((status.frames, status.decode_errors), (3, 0));
        assert_eq!(status.skipped_bytes, (MAX_CHUNK + 16) as u64);
        let ticks: Vec<u32> = rec
            .entries
            .iter()
            .map(|e| LogFrame::decode(e.frame.as_ref().unwrap()).unwrap().tick)
            .collect();
        assert_eq!(ticks, [1, 2, 3]);
    }

    /// Fails every open, as no serial device or as a missing port, counting the attempts.
    struct Failing {
        unusable: bool,
        opens: usize,
    }

    impl PortOpener for Failing {
        fn open(&mut self) -> Result<Box<dyn Read + Send>> {
            self.opens += 1;
            if self.unusable {
                Err(Unusable("port /dev/zero is not a serial device".into()).into())
            } else {
                anyhow::bail!("no such port")
            }
        }
    }

    #[test]
    fn the_loop_gives_up_on_a_port_that_can_never_be_monitored_and_retries_a_missing_one() {
        let dir = tempfile::tempdir().unwrap();
        let mut log = LogWriter::create(&dir.path().join("x.log"), false).unwrap();
        let options = MonitorOptions {
            max_frames: None,
            reopen_interval: Duration::ZERO,
        };
        let mut unusable = Failing {
            unusable: true,
            opens: 0,
        };
        let stop = AtomicBool::new(false);
        let e = run(&mut unusable, &mut log, &options, &stop, &mut |_| {}).unwrap_err();
        assert!(e.to_string().contains("not a serial device"), "{e}");
        assert_eq!(unusable.opens, 1);
        // a port that is not there (yet) is retried until stopped
        let mut missing = Failing {
            unusable: false,
            opens: 0,
        };
        let mut failures = 0;
        run(&mut missing, &mut log, &options, &stop, &mut |e| {
            if matches!(e, MonitorEvent::OpenFailed(_)) {
                failures += 1;
                if failures == 3 {
                    stop.store(true, Ordering::SeqCst);
                }
            }
        })
        .unwrap();
        assert_eq!(missing.opens, 3);
    }

    #[cfg(unix)]
    #[test]
    fn files_directories_and_devices_that_are_no_terminal_are_no_serial_ports() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("capture.bin");
        std::fs::write(&file, [0u8; 4]).unwrap();
        let opener = |port: &Path| SerialOpener {
            port: port.display().to_string(),
            baud: DEFAULT_BAUD,
        };
        for (port, what) in [
            (file.as_path(), "a regular file"),
            (dir.path(), "a directory"),
            (
                Path::new("/dev/zero"),
                "a character device that is not a terminal",
            ),
        ] {
            let e = opener(port).check().unwrap_err().to_string();
            assert!(e.contains(what) && e.contains("not a serial device"), "{e}");
        }
        assert!(opener(&dir.path().join("ttyACM7")).check().is_ok());
    }

    #[test]
    fn a_set_stop_flag_ends_the_loop_without_opening() {
        let mut opener = Unplugging {
            streams: VecDeque::new(),
            fail_next: false,
            opens: 0,
        };
        let dir = tempfile::tempdir().unwrap();
        let mut log = LogWriter::create(&dir.path().join("x.log"), false).unwrap();
        let status = run(
            &mut opener,
            &mut log,
            &MonitorOptions::default(),
            &AtomicBool::new(true),
            &mut |_| {},
        )
        .unwrap();
        assert_eq!((status.frames, opener.opens), (0, 0));
    }
}
