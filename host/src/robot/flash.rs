//! `host flash`: builds the firmware with a policy and writes it to a Zumo
//! through its avr109 bootloader with avrdude.
//!
//! Everything that can be checked is checked before anything is built or
//! written: the policy decodes and fits the hasher, the checkout is found,
//! a port is given, avrdude is installed. Then `scripts/build-firmware`
//! builds that policy (and robot id) into its own fresh output directory,
//! `target/flash/<policy CRC>-robot<id>/` (whatever `CARGO_TARGET_DIR` or
//! `FIRMWARE_OUT` the environment holds), the hex is checked to embed that
//! policy's CRC and robot id (`shared::FirmwareIdentity`), the robot is
//! sent into its bootloader, and once the bootloader's port *appears* (a
//! port that was there before does not count) avrdude writes the hex.
//!
//! Into the bootloader: when `--port` exists (the robot's own USB serial
//! port), the 1200-baud touch: open it at 1200 baud, drop DTR, close it;
//! the firmware stops its motors and lets the watchdog reset the chip into
//! the bootloader, whose port is a new one (another USB product id, no
//! serial number): the first serial port to appear that was not there
//! before the touch, or `--port` itself once it went away and came back.
//! Several new ports at once (several robots' bootloaders) are refused:
//! nothing tells them apart. When `--port` does not exist, or the touch
//! fails (firmware without USB), the user double-presses reset and the
//! port must appear.

use anyhow::{bail, Context, Result};
use shared::{FirmwareIdentity, StateHasher};
use sim::base::ranges;
use std::ffi::OsStr;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The build script, relative to the checkout.
const BUILD_SCRIPT: &str = "scripts/build-firmware";
/// Where `host flash` builds, relative to the checkout: one directory per
/// policy and robot.
const FLASH_BUILDS: &str = "target/flash";
/// How long to wait for the bootloader's port after asking for the double
/// press (the bootloader itself waits 8 s for the programmer).
pub const PORT_WAIT: Duration = Duration::from_secs(20);

/// A validated flashing job.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FlashPlan {
    /// The checkout's root directory.
    pub repo: PathBuf,
    /// The policy blob, absolute.
    pub policy: PathBuf,
    /// Its hasher (the firmware is built for it).
    pub hasher: StateHasher,
    /// The bootloader's serial port, if given.
    pub port: Option<String>,
    /// The policy blob's CRC-32 (the firmware embeds it).
    pub policy_crc: u32,
    /// The robot id built in (0: none given).
    pub robot_id: u8,
}

/// The robot's own sensor model, as a blob names it
/// ([`sim::scenario::trained_for::sensors_label`]).
pub const ROBOT_SENSORS: &str = "robot";

/// What `policy` was trained for, against a robot: refused when it names
/// another sensor model than the robot's (its states would mean what disc
/// sensors report, not what the photo-transistors and the Pixy do) unless
/// `any_sensors`; a warning when its arena is the thesis' square, which no
/// robot drives on. A blob that does not say (format version 1) passes.
pub fn check_trained_for(policy: &Path, any_sensors: bool) -> Result<Option<String>> {
    let blob = sim::control::policy_file::read(policy)?;
    let Some(t) = blob.trained_for() else {
        return Ok(None);
    };
    if t.sensors.as_str() != ROBOT_SENSORS && !any_sensors {
        bail!(
            "policy file {} was trained for the sensor model {} but a robot has its own ({ROBOT_SENSORS}): \
             its states would mean other readings on the robot (train with --sensors robot, \
             or pass --any-sensors to flash it anyway)",
            policy.display(),
            t.sensors.escape_debug()
        );
    }
    Ok((t.arena.as_str() == "thesis").then(|| {
        format!(
            "policy file {} was trained in the thesis' square arena, not on a screen: \
             the TV's size, pucks and robots differ",
            policy.display()
        )
    }))
}

impl FlashPlan {
    /// Validates the request: the policy decodes (and uses `hasher`, when
    /// one is asked for) and a checkout is found (`repo`, or the nearest
    /// ancestor of `cwd` holding one).
    pub fn new(
        policy: &Path,
        hasher: Option<StateHasher>,
        port: Option<String>,
        repo: Option<&Path>,
        cwd: &Path,
    ) -> Result<FlashPlan> {
        let blob = sim::control::policy_file::read(policy)?;
        if let Some(h) = hasher {
            if h != blob.hasher() {
                bail!(
                    "policy file {} uses hasher {} but --hasher asks for {h}: the firmware would refuse it \
                     (omit --hasher to build for the policy's own hasher)",
                    policy.display(),
                    blob.hasher()
                );
            }
        }
        let repo = match repo {
            Some(dir) => {
                if !is_checkout(dir) {
                    bail!("--repo {} is not a zumo-swarm checkout (no {BUILD_SCRIPT} and firmware/Cargo.toml)", dir.display());
                }
                dir.to_path_buf()
            }
            None => find_checkout(cwd)?,
        };
        let repo = repo
            .canonicalize()
            .with_context(|| format!("cannot resolve {}", repo.display()))?;
        let policy = policy
            .canonicalize()
            .with_context(|| format!("cannot resolve policy file {}", policy.display()))?;
        let bytes = ranges::read_file(&policy, &ranges::POLICY_FILE)
            .with_context(|| format!("cannot read policy file {}", policy.display()))?;
        let policy_crc = FirmwareIdentity::policy_crc_of(&bytes)
            .with_context(|| format!("policy file {} is too short", policy.display()))?;
        Ok(FlashPlan {
            repo,
            policy,
            hasher: blob.hasher(),
            port,
            policy_crc,
            robot_id: 0,
        })
    }

    /// The same plan for robot `id`.
    pub fn for_robot(self, id: u8) -> FlashPlan {
        FlashPlan {
            robot_id: id,
            ..self
        }
    }

    /// The identity the hex must embed.
    pub fn identity(&self) -> FirmwareIdentity {
        FirmwareIdentity {
            robot_id: self.robot_id,
            policy_crc: self.policy_crc,
        }
    }

    /// This build's own output directory.
    pub fn out_dir(&self) -> PathBuf {
        self.repo
            .join(FLASH_BUILDS)
            .join(format!("{:08x}-robot{}", self.policy_crc, self.robot_id))
    }

    /// The build script.
    pub fn build_script(&self) -> PathBuf {
        self.repo.join(BUILD_SCRIPT)
    }

    /// The environment the build script gets (`CARGO_TARGET_DIR` is
    /// removed from it: the script picks its own).
    pub fn build_env(&self) -> [(&'static str, String); 4] {
        [
            ("FIRMWARE_POLICY", self.policy.display().to_string()),
            ("FIRMWARE_HASHER", self.hasher.name().to_string()),
            ("FIRMWARE_ROBOT_ID", self.robot_id.to_string()),
            ("FIRMWARE_OUT", self.out_dir().display().to_string()),
        ]
    }

    /// The hex file the build writes.
    pub fn hex(&self) -> PathBuf {
        self.out_dir().join("firmware.hex")
    }

    /// Fails unless the hex at [`FlashPlan::hex`] embeds this plan's
    /// identity (policy CRC and robot id), and no other.
    pub fn check_hex(&self) -> Result<()> {
        let path = self.hex();
        let text = std::fs::read_to_string(&path)
            .with_context(|| format!("cannot read the built hex {}", path.display()))?;
        let image = hex_image(&text)
            .with_context(|| format!("the built hex {} is not Intel HEX", path.display()))?;
        let found: Vec<FirmwareIdentity> = FirmwareIdentity::find_all(&image).collect();
        if found != [self.identity()] {
            let what = match found.first() {
                None => "no firmware identity".to_string(),
                Some(f) => format!(
                    "policy CRC {:08x} and robot id {}",
                    f.policy_crc, f.robot_id
                ),
            };
            bail!(
                "the built hex {} embeds {what}, not policy {} (CRC {:08x}) for robot {}: a stale or foreign build; \
                 nothing was written to the robot",
                path.display(),
                self.policy.display(),
                self.policy_crc,
                self.robot_id
            );
        }
        Ok(())
    }

    /// avrdude's arguments for `port` (docs/firmware.md: avr109 at 57600,
    /// `-D` keeps the bootloader's erase scheme, EEPROM untouched).
    pub fn avrdude_args(&self, port: &str) -> Vec<String> {
        [
            "-p",
            "atmega32u4",
            "-c",
            "avr109",
            "-P",
            port,
            "-b",
            "57600",
            "-D",
            "-U",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([format!("flash:w:{}:i", self.hex().display())])
        .collect()
    }

    /// The exact commands a real run executes, as shell lines.
    pub fn describe(&self) -> String {
        let env: Vec<String> = self
            .build_env()
            .iter()
            .map(|(k, v)| format!("{k}={}", quote(v)))
            .collect();
        let port = self.port.as_deref().unwrap_or("PORT");
        let avrdude: Vec<String> = self.avrdude_args(port).iter().map(|a| quote(a)).collect();
        let mut out = String::new();
        out.push_str(&format!(
            "env -u CARGO_TARGET_DIR {} {}\n",
            env.join(" "),
            quote(&self.build_script().display().to_string())
        ));
        out.push_str(&format!(
            "# check that the hex embeds policy CRC {:08x} and robot id {}, then the 1200-baud touch: open {port} at \
             1200 baud and drop DTR (the robot resets into its bootloader; if {port} does not exist or the touch fails, \
             double-press the robot's reset button: its bootloader waits 8 s); once the bootloader's port appears \
             (a port new since the touch, or {port} back):\n",
            self.policy_crc, self.robot_id
        ));
        out.push_str(&format!("avrdude {}\n", avrdude.join(" ")));
        if self.port.is_none() {
            out.push_str("# PORT: pass --port (the bootloader's port, usually /dev/ttyACM0)\n");
        }
        out
    }
}

/// The bytes of an Intel HEX file (data records at their addresses, gaps
/// filled with 0xFF); every record's checksum is checked.
pub fn hex_image(text: &str) -> Result<Vec<u8>> {
    let mut image = Vec::new();
    let mut base = 0usize;
    for (n, line) in text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
    {
        let line = line.trim();
        let digits = line
            .strip_prefix(':')
            .with_context(|| format!("line {}: no ':'", n + 1))?;
        let bytes: Vec<u8> = (0..digits.len() / 2)
            .map(|i| u8::from_str_radix(digits.get(2 * i..2 * i + 2).unwrap_or("zz"), 16))
            .collect::<Result<_, _>>()
            .with_context(|| format!("line {}: not hex digits", n + 1))?;
        if digits.len() % 2 != 0 || bytes.len() < 5 || bytes.len() != 5 + usize::from(bytes[0]) {
            bail!("line {}: wrong length", n + 1);
        }
        if bytes.iter().fold(0u8, |s, b| s.wrapping_add(*b)) != 0 {
            bail!("line {}: bad checksum", n + 1);
        }
        let (addr, kind, data) = (
            usize::from(u16::from_be_bytes([bytes[1], bytes[2]])),
            bytes[3],
            &bytes[4..bytes.len() - 1],
        );
        match kind {
            0 => {
                let at = base + addr;
                if image.len() < at + data.len() {
                    image.resize(at + data.len(), 0xFF);
                }
                image[at..at + data.len()].copy_from_slice(data);
            }
            1 => break,
            2 if data.len() == 2 => base = usize::from(u16::from_be_bytes([data[0], data[1]])) << 4,
            4 if data.len() == 2 => {
                base = usize::from(u16::from_be_bytes([data[0], data[1]])) << 16
            }
            3 | 5 => {}
            _ => bail!("line {}: record type {kind} not understood", n + 1),
        }
    }
    Ok(image)
}

/// Quotes a shell word when it needs it.
fn quote(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_/.:=,+-@%".contains(c));
    if plain {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

fn is_checkout(dir: &Path) -> bool {
    dir.join(BUILD_SCRIPT).is_file() && dir.join("firmware/Cargo.toml").is_file()
}

/// The nearest ancestor of `start` (itself included) that is a checkout.
pub fn find_checkout(start: &Path) -> Result<PathBuf> {
    match start.ancestors().find(|d| is_checkout(d)) {
        Some(dir) => Ok(dir.to_path_buf()),
        None => bail!(
            "host flash builds the firmware from source and must run inside a zumo-swarm checkout: \
             no {BUILD_SCRIPT} with firmware/Cargo.toml in {} or any parent directory (cd into the checkout, or pass --repo)",
            start.display()
        ),
    }
}

/// `name` on a `PATH`-style list of directories.
pub fn find_program(name: &str, path: Option<&OsStr>) -> Option<PathBuf> {
    let path = path?;
    std::env::split_paths(path)
        .map(|dir| dir.join(name))
        .find(|p| is_executable(p))
}

#[cfg(unix)]
fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    p.metadata()
        .is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(p: &Path) -> bool {
    p.is_file()
}

/// The serial ports the system lists now (USB ones included), by name.
pub fn system_ports() -> Vec<String> {
    serialport::available_ports()
        .map(|ports| ports.into_iter().map(|p| p.port_name).collect())
        .unwrap_or_default()
}

/// The 1200-baud touch: opens `port` at 1200 baud, drops DTR, closes it.
pub fn touch(port: &str) -> Result<()> {
    let mut p = serialport::new(port, shared::identity::USB_TOUCH_BAUD)
        .timeout(Duration::from_millis(100))
        .open()
        .with_context(|| format!("cannot open {port} at 1200 baud"))?;
    p.write_data_terminal_ready(false)
        .with_context(|| format!("cannot drop DTR on {port}"))?;
    Ok(())
}

/// Watches for the bootloader's port after a touch: a port listed now
/// that was not listed before the touch, or that was and went away since
/// (`/dev/ttyACM0` coming back as the bootloader), or `port` itself back
/// after it went away.
#[derive(Clone, Debug)]
pub struct NewPort {
    port: String,
    before: Vec<String>,
    gone: Vec<String>,
    port_gone: bool,
}

impl NewPort {
    /// Starts watching, with the ports listed just before the touch.
    pub fn new(port: &str, before: Vec<String>) -> NewPort {
        NewPort {
            port: port.to_string(),
            before,
            gone: Vec::new(),
            port_gone: false,
        }
    }

    /// Looks at the ports listed now and whether `port` exists: the new
    /// port once exactly one appeared, an error if several did.
    pub fn check(&mut self, listed: &[String], port_exists: bool) -> Result<Option<String>> {
        self.port_gone |= !port_exists;
        for p in &self.before {
            if !listed.contains(p) && !self.gone.contains(p) {
                self.gone.push(p.clone());
            }
        }
        let mut new: Vec<String> = listed
            .iter()
            .filter(|p| !self.before.contains(p) || self.gone.contains(p))
            .cloned()
            .collect();
        if self.port_gone && port_exists && !new.contains(&self.port) {
            new.push(self.port.clone());
        }
        match new.len() {
            0 => Ok(None),
            1 => Ok(new.pop()),
            _ => bail!(
                "several new serial ports appeared ({}): several robots entering their bootloaders cannot be told \
                 apart (the bootloader has no serial number); flash one robot at a time. Nothing was written",
                new.join(", ")
            ),
        }
    }
}

/// Builds and flashes: checks the port and avrdude (`None`: not installed)
/// first, builds into the plan's fresh output, checks the hex's identity,
/// sends the robot into its bootloader (the module's touch, or the user's
/// double press), waits up to `port_wait` for the bootloader's port to
/// appear, runs avrdude on it. Progress goes to `out`; the build's and
/// avrdude's own output to this process's.
pub fn flash(
    plan: &FlashPlan,
    avrdude: Option<&Path>,
    port_wait: Duration,
    out: &mut dyn Write,
) -> Result<()> {
    let Some(port) = plan.port.as_deref() else {
        bail!(
            "--port is required to flash: the robot's USB serial port (e.g. /dev/ttyACM0 or its /dev/serial/by-id/ link, \
             `host monitor --list` lists ports), or the port its bootloader appears as after a double press of reset. \
             Nothing was built or written."
        );
    };
    let Some(avrdude) = avrdude else {
        bail!("avrdude is not installed or not on PATH (Debian/Ubuntu: sudo apt-get install avrdude). Nothing was built or written.");
    };
    writeln!(
        out,
        "flash: building the firmware with {} ({}, robot id {})",
        plan.policy.display(),
        plan.hasher,
        plan.robot_id
    )?;
    let out_dir = plan.out_dir();
    for stale in ["firmware.hex", "firmware.elf"] {
        match std::fs::remove_file(out_dir.join(stale)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                return Err(e).with_context(|| {
                    format!("cannot remove the old {}", out_dir.join(stale).display())
                });
            }
            _ => {}
        }
    }
    let status = Command::new(plan.build_script())
        .env_remove("CARGO_TARGET_DIR")
        .envs(plan.build_env())
        .current_dir(&plan.repo)
        .status()
        .with_context(|| format!("cannot run {}", plan.build_script().display()))?;
    if !status.success() {
        bail!(
            "building the firmware failed ({}: {status}); nothing was written to the robot",
            plan.build_script().display()
        );
    }
    if !plan.hex().is_file() {
        bail!(
            "the build did not produce {}; nothing was written to the robot",
            plan.hex().display()
        );
    }
    plan.check_hex()?;
    writeln!(
        out,
        "flash: the hex embeds policy CRC {:08x} and robot id {}",
        plan.policy_crc, plan.robot_id
    )?;
    let before = system_ports();
    let touched = Path::new(port).exists() && {
        match touch(port) {
            Ok(()) => true,
            Err(e) => {
                writeln!(out, "flash: the 1200-baud touch failed ({e:#})")?;
                false
            }
        }
    };
    let bootloader = if touched {
        writeln!(
            out,
            "flash: 1200-baud touch on {port}: the robot resets into its bootloader; waiting up to {} s for its port",
            port_wait.as_secs()
        )?;
        out.flush()?;
        let mut watch = NewPort::new(port, before);
        let start = Instant::now();
        loop {
            if let Some(found) = watch.check(&system_ports(), Path::new(port).exists())? {
                break found;
            }
            if start.elapsed() >= port_wait {
                bail!(
                    "no bootloader port appeared within {} s of the 1200-baud touch on {port}: double-press reset and \
                     run again. Nothing was written to the robot",
                    port_wait.as_secs()
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    } else {
        wait_for_double_press(port, port_wait, out)?;
        port.to_string()
    };
    writeln!(out, "flash: writing through {bootloader}")?;
    let status = Command::new(avrdude)
        .args(plan.avrdude_args(&bootloader))
        .status()
        .with_context(|| format!("cannot run {}", avrdude.display()))?;
    if !status.success() {
        bail!("avrdude failed ({status}); the robot keeps its bootloader, so double-press reset and try again");
    }
    writeln!(out, "flash: done; the robot runs the new firmware")?;
    Ok(())
}

/// Asks for the double press of reset and waits up to `port_wait` for
/// `port` to appear (one there already must go away first: it is not the
/// bootloader the user just started).
fn wait_for_double_press(port: &str, port_wait: Duration, out: &mut dyn Write) -> Result<()> {
    let mut was_there = Path::new(port).exists();
    writeln!(
        out,
        "flash: double-press the robot's reset button now; waiting up to {} s for {port} to appear",
        port_wait.as_secs()
    )?;
    if was_there {
        writeln!(out, "flash: {port} exists already: waiting for it to go away and come back (the bootloader you start now)")?;
    }
    out.flush()?;
    let start = Instant::now();
    loop {
        let there = Path::new(port).exists();
        if there && !was_there {
            return Ok(());
        }
        was_there &= there;
        if start.elapsed() >= port_wait {
            bail!(
                "port {port} did not appear within {} s: is the robot connected by USB, and was reset pressed twice quickly? \
                 Nothing was written to the robot",
                port_wait.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    const POLICY: &str = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../policies/oc-heuristic.policy"
    );

    fn script(path: &Path, body: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, format!("#!/bin/sh\n{body}\n")).unwrap();
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }

    /// An Intel HEX file of `image` at address 0.
    fn to_hex(image: &[u8]) -> String {
        let mut out = String::new();
        for (n, chunk) in image.chunks(16).enumerate() {
            let addr = (n * 16) as u16;
            let mut record = vec![chunk.len() as u8, (addr >> 8) as u8, addr as u8, 0];
            record.extend(chunk);
            let sum = record.iter().fold(0u8, |s, b| s.wrapping_add(*b));
            record.push(sum.wrapping_neg());
            out.push(':');
            out.extend(record.iter().map(|b| format!("{b:02X}")));
            out.push('\n');
        }
        out + ":00000001FF\n"
    }

    /// A fake checkout whose build script records its environment and
    /// copies `hex` (in the checkout) to `$FIRMWARE_OUT/firmware.hex`.
    fn fake_checkout(dir: &Path) -> PathBuf {
        let repo = dir.join("repo with space");
        std::fs::create_dir_all(repo.join("firmware")).unwrap();
        std::fs::write(repo.join("firmware/Cargo.toml"), "").unwrap();
        script(
            &repo.join(BUILD_SCRIPT),
            "echo \"$FIRMWARE_POLICY $FIRMWARE_HASHER $FIRMWARE_ROBOT_ID $FIRMWARE_OUT ${CARGO_TARGET_DIR:-unset}\" > built; \
             mkdir -p \"$FIRMWARE_OUT\"; cp hex \"$FIRMWARE_OUT/firmware.hex\"",
        );
        repo
    }

    /// The hex a build of `plan` writes: some code around its identity.
    fn good_hex(plan: &FlashPlan) -> String {
        let mut image = vec![0x0Cu8; 40];
        image.extend(plan.identity().to_bytes());
        image.extend([0x95u8; 7]);
        to_hex(&image)
    }
    #[test]
    fn the_plan_names_the_exact_commands() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let plan = FlashPlan::new(
            Path::new(POLICY),
            None,
            Some("/dev/ttyACM0".into()),
            None,
            &repo.join("firmware"),
        )
        .unwrap()
        .for_robot(4);
        let repo = repo.canonicalize().unwrap();
        let policy = Path::new(POLICY).canonicalize().unwrap();
        let crc = FirmwareIdentity::policy_crc_of(&std::fs::read(&policy).unwrap()).unwrap();
        assert_eq!(plan.hasher, StateHasher::Original);
        assert_eq!(
            plan.describe(),
            format!(
                "env -u CARGO_TARGET_DIR FIRMWARE_POLICY={} FIRMWARE_HASHER=original FIRMWARE_ROBOT_ID=4 FIRMWARE_OUT='{}/target/flash/{crc:08x}-robot4' '{}/scripts/build-firmware'\n\
                 # check that the hex embeds policy CRC {crc:08x} and robot id 4, then the 1200-baud touch: open /dev/ttyACM0 at 1200 baud and drop DTR (the robot resets into its bootloader; if /dev/ttyACM0 does not exist or the touch fails, double-press the robot's reset button: its bootloader waits 8 s); once the bootloader's port appears (a port new since the touch, or /dev/ttyACM0 back):\n\
                 avrdude -p atmega32u4 -c avr109 -P /dev/ttyACM0 -b 57600 -D -U 'flash:w:{}/target/flash/{crc:08x}-robot4/firmware.hex:i'\n",
                policy.display(),
                repo.display(),
                repo.display(),
                repo.display()
            )
        );
    }

    #[test]
    fn after_a_touch_the_bootloaders_port_is_the_one_that_appears() {
        let s = |v: &[&str]| v.iter().map(|p| p.to_string()).collect::<Vec<_>>();
        // The robot's port goes away and comes back under its name.
        let mut w = NewPort::new("/dev/ttyACM0", s(&["/dev/ttyACM0", "/dev/ttyACM1"]));
        assert_eq!(
            w.check(&s(&["/dev/ttyACM0", "/dev/ttyACM1"]), true)
                .unwrap(),
            None
        );
        assert_eq!(w.check(&s(&["/dev/ttyACM1"]), false).unwrap(), None);
        assert_eq!(
            w.check(&s(&["/dev/ttyACM0", "/dev/ttyACM1"]), true)
                .unwrap(),
            Some("/dev/ttyACM0".to_string())
        );
        // Given by its by-id link (which the bootloader does not bring
        // back): the bootloader's port is a new name.
        let by_id = "/dev/serial/by-id/usb-zumo-swarm_Zumo_32U4_robot_robot-003-if00";
        let mut w = NewPort::new(by_id, s(&["/dev/ttyACM0", "/dev/ttyACM1"]));
        assert_eq!(w.check(&s(&["/dev/ttyACM1"]), false).unwrap(), None);
        assert_eq!(
            w.check(&s(&["/dev/ttyACM1", "/dev/ttyACM2"]), false)
                .unwrap(),
            Some("/dev/ttyACM2".to_string())
        );
        // Two bootloaders at once cannot be told apart.
        let mut w = NewPort::new("/dev/ttyACM0", s(&["/dev/ttyACM0"]));
        let e = w
            .check(&s(&["/dev/ttyACM1", "/dev/ttyACM2"]), false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("several new serial ports") && e.contains("one robot at a time"),
            "{e}"
        );
    }

    #[test]
    fn intel_hex_is_read_with_its_checksums() {
        let image: Vec<u8> = (0..40).collect();
        assert_eq!(hex_image(&to_hex(&image)).unwrap(), image);
        let mut bad = to_hex(&image);
        bad.replace_range(9..10, if &bad[9..10] == "0" { "1" } else { "0" });
        assert!(hex_image(&bad)
            .unwrap_err()
            .to_string()
            .contains("checksum"));
        assert!(hex_image("garbage").is_err());
    }

    #[test]
    fn bad_requests_fail_before_anything_runs() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let e = format!(
            "{:#}",
            FlashPlan::new(
                Path::new(POLICY),
                Some(StateHasher::Bits9),
                None,
                None,
                &repo
            )
            .unwrap_err()
        );
        assert!(
            e.contains("uses hasher original") && e.contains("bits9"),
            "{e}"
        );
        let bad = dir.path().join("bad.policy");
        std::fs::write(&bad, b"QPOL\x01garbage").unwrap();
        let e = format!(
            "{:#}",
            FlashPlan::new(&bad, None, None, None, &repo).unwrap_err()
        );
        assert!(e.contains("bad.policy"), "{e}");
        let e = format!(
            "{:#}",
            FlashPlan::new(Path::new(POLICY), None, None, None, dir.path()).unwrap_err()
        );
        assert!(e.contains("must run inside a zumo-swarm checkout"), "{e}");

        let plan = FlashPlan::new(Path::new(POLICY), None, None, Some(&repo), dir.path()).unwrap();
        let avrdude = dir.path().join("avrdude");
        let e = flash(&plan, Some(&avrdude), Duration::ZERO, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("--port is required"), "{e}");
        let with_port = FlashPlan {
            port: Some("/dev/ttyACM0".into()),
            ..plan
        };
        let e = flash(&with_port, None, Duration::ZERO, &mut Vec::new())
            .unwrap_err()
            .to_string();
        assert!(e.contains("avrdude is not installed"), "{e}");
        assert!(!repo.join("built").exists(), "the build ran");
    }

    #[test]
    fn a_stale_or_foreign_hex_is_never_flashed() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let bin = dir.path().join("bin");
        script(
            &bin.join("avrdude"),
            &format!("echo \"$@\" > '{}/avrdude-args'", dir.path().display()),
        );
        let port = dir.path().join("ttyACM9");
        let plan = FlashPlan::new(
            Path::new(POLICY),
            None,
            Some(port.display().to_string()),
            Some(&repo),
            dir.path(),
        )
        .unwrap()
        .for_robot(2);
        // A build of robot 3, or of another policy, or no identity at all.
        for other in [
            plan.clone().for_robot(3),
            FlashPlan {
                policy_crc: 7,
                ..plan.clone()
            },
        ] {
            std::fs::write(repo.join("hex"), good_hex(&other)).unwrap();
            let e = flash(
                &plan,
                Some(&bin.join("avrdude")),
                Duration::ZERO,
                &mut Vec::new(),
            )
            .unwrap_err()
            .to_string();
            assert!(
                e.contains("stale or foreign build") && e.contains("nothing was written"),
                "{e}"
            );
        }
        std::fs::write(repo.join("hex"), to_hex(&[0u8; 64])).unwrap();
        let e = flash(
            &plan,
            Some(&bin.join("avrdude")),
            Duration::ZERO,
            &mut Vec::new(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("no firmware identity"), "{e}");
        assert!(!dir.path().join("avrdude-args").exists());
    }

    #[test]
    fn a_real_run_builds_fresh_waits_for_the_port_to_appear_and_calls_avrdude() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let bin = dir.path().join("bin");
        script(
            &bin.join("avrdude"),
            &format!("echo \"$@\" > '{}/avrdude-args'", dir.path().display()),
        );
        assert_eq!(
            find_program("avrdude", Some(bin.as_os_str())),
            Some(bin.join("avrdude"))
        );
        assert_eq!(find_program("avrdude", Some(dir.path().as_os_str())), None);

        let port = dir.path().join("ttyACM9");
        let plan = FlashPlan::new(
            Path::new(POLICY),
            None,
            Some(port.display().to_string()),
            Some(&repo),
            dir.path(),
        )
        .unwrap()
        .for_robot(5);
        std::fs::write(repo.join("hex"), good_hex(&plan)).unwrap();
        let mut out = Vec::new();
        let e = flash(&plan, Some(&bin.join("avrdude")), Duration::ZERO, &mut out)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("did not appear") && e.contains("Nothing was written"),
            "{e}"
        );
        assert!(String::from_utf8(out)
            .unwrap()
            .contains("double-press the robot's reset button now"));
        assert!(!dir.path().join("avrdude-args").exists());

        // A port that is there already does not count: it must go away and come back.
        std::fs::write(&port, b"").unwrap();
        let e = flash(
            &plan,
            Some(&bin.join("avrdude")),
            Duration::from_millis(200),
            &mut Vec::new(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("did not appear"), "{e}");
        assert!(!dir.path().join("avrdude-args").exists());
        let replug = {
            let port = port.clone();
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_millis(300));
                std::fs::remove_file(&port).unwrap();
                std::thread::sleep(Duration::from_millis(300));
                std::fs::write(&port, b"").unwrap();
            })
        };
        // The environment's target directory and output are not the build's.
        std::env::set_var("CARGO_TARGET_DIR", dir.path().join("elsewhere"));
        let mut out = Vec::new();
        let result = flash(
            &plan,
            Some(&bin.join("avrdude")),
            Duration::from_secs(20),
            &mut out,
        );
        std::env::remove_var("CARGO_TARGET_DIR");
        replug.join().unwrap();
        result.unwrap();
        assert!(String::from_utf8(out).unwrap().contains("exists already"));
        let built = std::fs::read_to_string(repo.join("built")).unwrap();
        assert_eq!(
            built.trim(),
            format!(
                "{} original 5 {} unset",
                plan.policy.display(),
                plan.out_dir().display()
            )
        );
        let args = std::fs::read_to_string(dir.path().join("avrdude-args")).unwrap();
        assert_eq!(
            args.trim(),
            plan.avrdude_args(&port.display().to_string()).join(" ")
        );
    }
}
