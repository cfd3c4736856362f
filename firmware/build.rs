//! Embeds the policy: decodes the blob with `shared`'s decoder, checks its
//! hasher, and generates `policy.rs` (the packed table and each action's
//! motor outputs, `shared::RobotProfile::action_motors` computed here on
//! the host so the AVR needs no floats).
//!
//! - `FIRMWARE_POLICY`: the blob (default `policies/oc-heuristic.policy`;
//!   a relative path is taken from the workspace root).
//! - `FIRMWARE_HASHER`: the hasher the firmware is built for (a name or bit
//!   count as in `docs/state-hash.md`; default `original`). A blob of
//!   another hasher fails the build.
//! - `FIRMWARE_ROBOT_ID`: the robot's id, 0..=255 (default 0, none given),
//!   stored with the policy's CRC in the image's identity record
//!   (`shared::FirmwareIdentity`) and sent in every log frame.
//!
//! It also writes `source_hash.s`, an assembler section `.zumo.sources`
//! (not loaded: the flash is unchanged) holding the marker of the
//! sources' hash (`src/source_hash.rs`), which `src/main.rs` links in.

#[path = "src/source_hash.rs"]
mod source_hash;

use shared::{FirmwareIdentity, PolicyBlob, RobotProfile, StateHasher};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::{env, fs};

const DEFAULT_POLICY: &str = "policies/oc-heuristic.policy";
const DEFAULT_HASHER: &str = "original";

fn fail(message: &str) -> ! {
    eprintln!("error: {message}");
    std::process::exit(1);
}

fn main() {
    println!("cargo:rerun-if-env-changed=FIRMWARE_POLICY");
    println!("cargo:rerun-if-env-changed=FIRMWARE_HASHER");
    println!("cargo:rerun-if-env-changed=FIRMWARE_ROBOT_ID");
    println!("cargo:rerun-if-changed=build.rs");
    let root =
        PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"))
            .join("..");
    let policy = root.join(env::var("FIRMWARE_POLICY").unwrap_or_else(|_| DEFAULT_POLICY.into()));
    println!("cargo:rerun-if-changed={}", policy.display());

    let bytes = fs::read(&policy)
        .unwrap_or_else(|e| fail(&format!("policy file {}: {e}", policy.display())));
    let blob = PolicyBlob::decode(&bytes)
        .unwrap_or_else(|e| fail(&format!("policy file {}: {e}", policy.display())));
    let hasher_name = env::var("FIRMWARE_HASHER").unwrap_or_else(|_| DEFAULT_HASHER.into());
    let expected = StateHasher::from_name(&hasher_name).unwrap_or_else(|| {
        fail(&format!(
            "FIRMWARE_HASHER={hasher_name} is not a hasher ({})",
            StateHasher::NAMES
        ))
    });
    if blob.hasher() != expected {
        fail(&format!(
            "policy file {}: its hasher is {} but the firmware is built for {expected}; \
             build with FIRMWARE_HASHER={} to use it",
            policy.display(),
            blob.hasher(),
            blob.hasher().name()
        ));
    }

    let robot_id = match env::var("FIRMWARE_ROBOT_ID") {
        Ok(v) => v.parse::<u8>().unwrap_or_else(|_| {
            fail(&format!(
                "FIRMWARE_ROBOT_ID={v} is not a robot id (0..=255)"
            ))
        }),
        Err(_) => 0,
    };
    let policy_crc =
        FirmwareIdentity::policy_crc_of(&bytes).unwrap_or_else(|| fail("policy file too short"));
    let identity = FirmwareIdentity {
        robot_id,
        policy_crc,
    }
    .to_bytes();

    let motors = RobotProfile::ZUMO.action_motors(blob.actions());
    let mut out = String::new();
    let hasher = format!("{:?}", blob.hasher());
    let packed = blob.sets().packed();
    writeln!(out, "/// Path of the embedded policy blob.").unwrap();
    writeln!(
        out,
        "pub const POLICY_PATH: &str = {:?};",
        policy.display().to_string()
    )
    .unwrap();
    writeln!(
        out,
        "/// The embedded policy blob itself (for host tests; not linked into the AVR image)."
    )
    .unwrap();
    writeln!(
        out,
        "pub const POLICY_BLOB: &[u8] = include_bytes!({:?});",
        policy.display().to_string()
    )
    .unwrap();
    writeln!(
        out,
        "/// The image's identity record: robot id {robot_id}, policy CRC-32 {policy_crc:#010x}."
    )
    .unwrap();
    writeln!(
        out,
        "pub const IDENTITY: [u8; shared::FirmwareIdentity::LEN] = {identity:?};"
    )
    .unwrap();
    let serial = FirmwareIdentity::usb_serial(robot_id);
    writeln!(
        out,
        "/// The USB serial number (`shared::FirmwareIdentity::usb_serial`)."
    )
    .unwrap();
    writeln!(
        out,
        "pub const USB_SERIAL: &str = {:?};",
        String::from_utf8_lossy(&serial)
    )
    .unwrap();
    writeln!(out, "/// The policy's state hasher.").unwrap();
    writeln!(
        out,
        "pub const HASHER: shared::StateHasher = shared::StateHasher::{hasher};"
    )
    .unwrap();
    writeln!(
        out,
        "/// Each state's best actions, 4 bits per state (`shared::ActionSets` layout; one action per state for a blob of format version 1)."
    )
    .unwrap();
    writeln!(
        out,
        "pub const POLICY_SETS: [u8; {}] = {:?};",
        packed.len(),
        packed
    )
    .unwrap();
    writeln!(out, "/// Each action's motor commands and outputs (`shared::RobotProfile::ZUMO.action_motors`).").unwrap();
    writeln!(
        out,
        "pub const MOTORS: shared::ActionMotors = shared::ActionMotors {{"
    )
    .unwrap();
    write!(out, "    commands: [").unwrap();
    for c in motors.commands {
        write!(
            out,
            "shared::MotorCommand {{ left: {}, right: {} }}, ",
            c.left, c.right
        )
        .unwrap();
    }
    writeln!(out, "],\n    outputs: [").unwrap();
    for o in motors.outputs {
        writeln!(
            out,
            "        shared::DriveOutputs {{ left: shared::MotorOutput {{ duty: {}, dir_high: {} }}, right: shared::MotorOutput {{ duty: {}, dir_high: {} }} }},",
            o.left.duty, o.left.dir_high, o.right.duty, o.right.dir_high
        )
        .unwrap();
    }
    writeln!(out, "    ],\n}};").unwrap();
    let out_dir = PathBuf::from(env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let dest = out_dir.join("policy.rs");
    fs::write(&dest, out).unwrap_or_else(|e| fail(&format!("{}: {e}", dest.display())));

    for source in source_hash::SOURCES {
        println!("cargo:rerun-if-changed={}", root.join(source).display());
    }
    let hash = source_hash::of_workspace(&root)
        .unwrap_or_else(|e| fail(&format!("hashing the sources: {e}")));
    let asm = format!(
        ".pushsection .zumo.sources,\"\",@progbits\n.asciz \"{}\"\n.popsection\n",
        source_hash::marker(hash)
    );
    let dest = out_dir.join("source_hash.s");
    fs::write(&dest, asm).unwrap_or_else(|e| fail(&format!("{}: {e}", dest.display())));
}
