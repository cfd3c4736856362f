//! `host flash`: builds the firmware with a policy and writes it to a Zumo
//! through its avr109 bootloader with avrdude.
//!
//! Everything that can be checked is checked before anything is built or
//! written: the policy decodes and fits the hasher, the checkout is found,
//! a port is given, avrdude is installed. Then `scripts/build-firmware`
//! runs with `FIRMWARE_POLICY` / `FIRMWARE_HASHER`, the user double-presses
//! reset, and once the bootloader's port exists avrdude writes the hex.

use anyhow::{bail, Context, Result};
use shared::StateHasher;
use std::ffi::OsStr;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// The build script, relative to the checkout.
const BUILD_SCRIPT: &str = "scripts/build-firmware";
/// The hex it writes, relative to the checkout.
const HEX: &str = "target/avr-none/firmware/firmware.hex";
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
}

impl FlashPlan {
    /// Validates the request: the policy decodes (and uses `hasher`, when
    /// one is asked for) and a checkout is found (`repo`, or the nearest
    /// ancestor of `cwd` holding one).
    pub fn new(policy: &Path, hasher: Option<StateHasher>, port: Option<String>, repo: Option<&Path>, cwd: &Path) -> Result<FlashPlan> {
        let blob = sim::policy_file::read(policy)?;
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
        let repo = repo.canonicalize().with_context(|| format!("cannot resolve {}", repo.display()))?;
        let policy = policy.canonicalize().with_context(|| format!("cannot resolve policy file {}", policy.display()))?;
        Ok(FlashPlan { repo, policy, hasher: blob.hasher(), port })
    }

    /// The build script.
    pub fn build_script(&self) -> PathBuf {
        self.repo.join(BUILD_SCRIPT)
    }

    /// The environment the build script gets.
    pub fn build_env(&self) -> [(&'static str, String); 2] {
        [("FIRMWARE_POLICY", self.policy.display().to_string()), ("FIRMWARE_HASHER", self.hasher.name().to_string())]
    }

    /// The hex file the build writes.
    pub fn hex(&self) -> PathBuf {
        self.repo.join(HEX)
    }

    /// avrdude's arguments for `port` (docs/firmware.md: avr109 at 57600,
    /// `-D` keeps the bootloader's erase scheme, EEPROM untouched).
    pub fn avrdude_args(&self, port: &str) -> Vec<String> {
        ["-p", "atmega32u4", "-c", "avr109", "-P", port, "-b", "57600", "-D", "-U"]
            .iter()
            .map(|s| s.to_string())
            .chain([format!("flash:w:{}:i", self.hex().display())])
            .collect()
    }

    /// The exact commands a real run executes, as shell lines.
    pub fn describe(&self) -> String {
        let env: Vec<String> = self.build_env().iter().map(|(k, v)| format!("{k}={}", quote(v))).collect();
        let port = self.port.as_deref().unwrap_or("PORT");
        let avrdude: Vec<String> = self.avrdude_args(port).iter().map(|a| quote(a)).collect();
        let mut out = String::new();
        out.push_str(&format!("{} {}\n", env.join(" "), quote(&self.build_script().display().to_string())));
        out.push_str(&format!(
            "# then double-press the robot's reset button (its bootloader waits 8 s); once {port} exists:\n"
        ));
        out.push_str(&format!("avrdude {}\n", avrdude.join(" ")));
        if self.port.is_none() {
            out.push_str("# PORT: pass --port (the bootloader's port, usually /dev/ttyACM0)\n");
        }
        out
    }
}

/// Quotes a shell word when it needs it.
fn quote(word: &str) -> String {
    let plain = !word.is_empty() && word.chars().all(|c| c.is_ascii_alphanumeric() || "_/.:=,+-@%".contains(c));
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
    std::env::split_paths(path).map(|dir| dir.join(name)).find(|p| is_executable(p))
}

#[cfg(unix)]
fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    p.metadata().is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(not(unix))]
fn is_executable(p: &Path) -> bool {
    p.is_file()
}

/// Builds and flashes: checks the port and avrdude (`None`: not installed)
/// first, builds, asks for the double press, waits up to `port_wait` for
/// the port, runs avrdude. Progress goes to `out`; the build's and
/// avrdude's own output to this process's.
pub fn flash(plan: &FlashPlan, avrdude: Option<&Path>, port_wait: Duration, out: &mut dyn Write) -> Result<()> {
    let Some(port) = plan.port.as_deref() else {
        bail!(
            "--port is required to flash: after a double press of reset the bootloader appears as a serial port \
             (usually /dev/ttyACM0; `host monitor --list` lists ports). Nothing was built or written."
        );
    };
    let Some(avrdude) = avrdude else {
        bail!("avrdude is not installed or not on PATH (Debian/Ubuntu: sudo apt-get install avrdude). Nothing was built or written.");
    };
    writeln!(out, "flash: building the firmware with {} ({})", plan.policy.display(), plan.hasher)?;
    let status = Command::new(plan.build_script())
        .envs(plan.build_env())
        .current_dir(&plan.repo)
        .status()
        .with_context(|| format!("cannot run {}", plan.build_script().display()))?;
    if !status.success() {
        bail!("building the firmware failed ({}: {status}); nothing was written to the robot", plan.build_script().display());
    }
    if !plan.hex().is_file() {
        bail!("the build did not produce {}; nothing was written to the robot", plan.hex().display());
    }
    writeln!(out, "flash: double-press the robot's reset button now; waiting up to {} s for {port}", port_wait.as_secs())?;
    out.flush()?;
    let start = Instant::now();
    while !Path::new(port).exists() {
        if start.elapsed() >= port_wait {
            bail!(
                "port {port} did not appear within {} s: is the robot connected by USB, and was reset pressed twice quickly? \
                 Nothing was written to the robot",
                port_wait.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let status = Command::new(avrdude)
        .args(plan.avrdude_args(port))
        .status()
        .with_context(|| format!("cannot run {}", avrdude.display()))?;
    if !status.success() {
        bail!("avrdude failed ({status}); the robot keeps its bootloader, so double-press reset and try again");
    }
    writeln!(out, "flash: done; the robot runs the new firmware")?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    const POLICY: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../policies/oc-heuristic.policy");

    fn script(path: &Path, body: &str) {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, format!("#!/bin/sh\n{body}\n")).unwrap();
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }

    /// A fake checkout whose build script records its environment and
    /// writes the hex.
    fn fake_checkout(dir: &Path) -> PathBuf {
        let repo = dir.join("repo with space");
        std::fs::create_dir_all(repo.join("firmware")).unwrap();
        std::fs::write(repo.join("firmware/Cargo.toml"), "").unwrap();
        script(
            &repo.join(BUILD_SCRIPT),
            "echo \"$FIRMWARE_POLICY $FIRMWARE_HASHER\" > built; mkdir -p target/avr-none/firmware; echo hex > target/avr-none/firmware/firmware.hex",
        );
        repo
    }

    #[test]
    fn the_plan_names_the_exact_commands() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let plan = FlashPlan::new(Path::new(POLICY), None, Some("/dev/ttyACM0".into()), None, &repo.join("firmware")).unwrap();
        let repo = repo.canonicalize().unwrap();
        let policy = Path::new(POLICY).canonicalize().unwrap();
        assert_eq!(plan.hasher, StateHasher::Original);
        assert_eq!(
            plan.describe(),
            format!(
                "FIRMWARE_POLICY={} FIRMWARE_HASHER=original '{}/scripts/build-firmware'\n\
                 # then double-press the robot's reset button (its bootloader waits 8 s); once /dev/ttyACM0 exists:\n\
                 avrdude -p atmega32u4 -c avr109 -P /dev/ttyACM0 -b 57600 -D -U 'flash:w:{}/target/avr-none/firmware/firmware.hex:i'\n",
                policy.display(),
                repo.display(),
                repo.display()
            )
        );
    }

    #[test]
    fn bad_requests_fail_before_anything_runs() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let e = format!("{:#}", FlashPlan::new(Path::new(POLICY), Some(StateHasher::Bits9), None, None, &repo).unwrap_err());
        assert!(e.contains("uses hasher original") && e.contains("bits9"), "{e}");
        let bad = dir.path().join("bad.policy");
        std::fs::write(&bad, b"QPOL\x01garbage").unwrap();
        let e = format!("{:#}", FlashPlan::new(&bad, None, None, None, &repo).unwrap_err());
        assert!(e.contains("bad.policy"), "{e}");
        let e = format!("{:#}", FlashPlan::new(Path::new(POLICY), None, None, None, dir.path()).unwrap_err());
        assert!(e.contains("must run inside a zumo-swarm checkout"), "{e}");

        let plan = FlashPlan::new(Path::new(POLICY), None, None, Some(&repo), dir.path()).unwrap();
        let avrdude = dir.path().join("avrdude");
        let e = flash(&plan, Some(&avrdude), Duration::ZERO, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("--port is required"), "{e}");
        let with_port = FlashPlan { port: Some("/dev/ttyACM0".into()), ..plan };
        let e = flash(&with_port, None, Duration::ZERO, &mut Vec::new()).unwrap_err().to_string();
        assert!(e.contains("avrdude is not installed"), "{e}");
        assert!(!repo.join("built").exists(), "the build ran");
    }

    #[test]
    fn a_real_run_builds_waits_for_the_port_and_calls_avrdude() {
        let dir = tempfile::tempdir().unwrap();
        let repo = fake_checkout(dir.path());
        let bin = dir.path().join("bin");
        script(&bin.join("avrdude"), &format!("echo \"$@\" > '{}/avrdude-args'", dir.path().display()));
        assert_eq!(find_program("avrdude", Some(bin.as_os_str())), Some(bin.join("avrdude")));
        assert_eq!(find_program("avrdude", Some(dir.path().as_os_str())), None);

        let missing = dir.path().join("ttyACM9");
        let plan = FlashPlan::new(Path::new(POLICY), None, Some(missing.display().to_string()), Some(&repo), dir.path()).unwrap();
        let mut out = Vec::new();
        let e = flash(&plan, Some(&bin.join("avrdude")), Duration::ZERO, &mut out).unwrap_err().to_string();
        assert!(e.contains("did not appear") && e.contains("Nothing was written"), "{e}");
        assert!(String::from_utf8(out).unwrap().contains("double-press the robot's reset button now"));
        assert!(!dir.path().join("avrdude-args").exists());

        std::fs::write(&missing, b"").unwrap();
        flash(&plan, Some(&bin.join("avrdude")), Duration::ZERO, &mut Vec::new()).unwrap();
        let built = std::fs::read_to_string(repo.join("built")).unwrap();
        assert_eq!(built.trim(), format!("{} original", plan.policy.display()));
        let args = std::fs::read_to_string(dir.path().join("avrdude-args")).unwrap();
        assert_eq!(args.trim(), plan.avrdude_args(&missing.display().to_string()).join(" "));
    }
}
