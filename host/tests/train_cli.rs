//! `host train` end to end: outputs, resume, RL2 seeding, the trained
//! policy under `host run`, and bad inputs refused with a clear error.

use assert_cmd::Command;
use std::path::Path;

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

/// Runs `host` in `dir` with `args`, expects success, returns stdout.
fn ok(dir: &Path, args: &[&str]) -> String {
    let out = host().current_dir(dir).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Runs `host` in `dir` with `args`, expects failure, returns stderr.
fn fails(dir: &Path, args: &[&str]) -> String {
    let out = host().current_dir(dir).args(args).output().unwrap();
    assert!(!out.status.success(), "{args:?} succeeded");
    String::from_utf8(out.stderr).unwrap()
}

const QUICK: [&str; 6] = [
    "train",
    "--robots",
    "4",
    "--pucks",
    "60",
    "--checkpoint-every=1000",
];

#[test]
fn train_writes_policy_and_checkpoint_under_out_and_summarises() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = ok(d, &[&QUICK[..], &["--steps", "3000"]].concat());
    for key in [
        "formations",
        "stuck episodes",
        "steps per second",
        "states visited",
        "of 256",
    ] {
        assert!(text.contains(key), "missing {key}: {text}");
    }
    let policy = d.join("out/annulus-original.policy");
    assert!(policy.is_file() && d.join("out/annulus-original.ckpt").is_file());
    assert!(
        !d.join("policies").exists(),
        "training never writes policies/ by default"
    );

    let inspect = ok(d, &["policy", "inspect", policy.to_str().unwrap()]);
    assert!(
        inspect.contains("annulus") && inspect.contains("annulus-original"),
        "{inspect}"
    );
    let run = ok(
        d,
        &[
            "run",
            "--steps",
            "500",
            "--controller",
            &format!("policy:{}", policy.display()),
        ],
    );
    assert!(run.contains("formations"), "{run}");
}

#[test]
fn resuming_continues_exactly_where_the_run_stopped() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(
        d,
        &[&QUICK[..], &["--steps", "5000", "--name", "long"]].concat(),
    );
    ok(
        d,
        &[&QUICK[..], &["--steps", "3000", "--name", "split"]].concat(),
    );
    let resumed = ok(
        d,
        &[
            "train",
            "--resume",
            "out/split.ckpt",
            "--steps",
            "2000",
            "--name",
            "long",
            "--out",
            "again",
        ],
    );
    assert!(resumed.contains("run total 5000"), "{resumed}");
    let a = std::fs::read(d.join("out/long.policy")).unwrap();
    let b = std::fs::read(d.join("again/long.policy")).unwrap();
    assert_eq!(a, b, "train(3000) + resume(2000) differs from train(5000)");

    // RL2: a new run seeded with the table
    let seeded = ok(
        d,
        &[
            &QUICK[..],
            &[
                "--steps",
                "1000",
                "--init-from",
                "out/long.ckpt",
                "--name",
                "rl2",
            ],
        ]
        .concat(),
    );
    assert!(seeded.contains("run total 1000"));
    let from_blob = ok(
        d,
        &[
            &QUICK[..],
            &[
                "--steps",
                "1000",
                "--init-from",
                "out/long.policy",
                "--name",
                "b",
            ],
        ]
        .concat(),
    );
    assert!(from_blob.contains("run total 1000"));
}

#[test]
fn a_config_file_sets_everything_and_flags_override_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("run.toml"),
        "field = \"letter:L\"\nrobots = 3\npucks = 40\nsteps = 1500\n[learn]\nhasher = \"bits7\"\n[output]\ndir = \"res\"\nname = \"ell\"\n",
    )
    .unwrap();
    let text = ok(d, &["train", "--config", "run.toml", "--hasher", "bits9"]);
    assert!(
        text.contains("run total 1500") && text.contains("of 512"),
        "{text}"
    );
    let inspect = ok(d, &["policy", "inspect", "res/ell.policy"]);
    assert!(inspect.contains("letter:L"), "{inspect}");
}

#[test]
fn bad_inputs_are_refused_with_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    assert!(fails(d, &["train", "--hasher", "bits12"]).contains("unknown hasher \"bits12\""));
    assert!(fails(d, &["train", "--reward", "money"]).contains("unknown reward \"money\""));
    assert!(fails(d, &["train", "--sensors", "sonar"]).contains("unknown sensor model \"sonar\""));
    assert!(fails(d, &["train", "--alpha", "1.5", "--steps", "10"]).contains("learn.alpha = 1.5"));
    assert!(fails(d, &["train", "--name", "../x", "--steps", "10"]).contains("path separators"));

    std::fs::write(d.join("bad.toml"), "robots = 4\n\n[learn\nalpha = 0.1\n").unwrap();
    let e = fails(d, &["train", "--config", "bad.toml"]);
    assert!(e.contains("bad.toml") && e.contains("line 3"), "{e}");
    std::fs::write(d.join("typo.toml"), "robots = 4\n[learn]\nalpah = 0.1\n").unwrap();
    let e = fails(d, &["train", "--config", "typo.toml"]);
    assert!(e.contains("alpah") && e.contains("line 3"), "{e}");

    ok(
        d,
        &[
            &QUICK[..],
            &["--steps", "500", "--hasher", "bits7", "--name", "seven"],
        ]
        .concat(),
    );
    // a checkpoint of another hasher is refused; a policy blob of a
    // coarser state starts a finer one lifted, never a coarser one
    let e = fails(
        d,
        &["train", "--steps", "10", "--init-from", "out/seven.ckpt"],
    );
    assert!(
        e.contains("bits7") && e.contains("original") && e.contains("out/seven.ckpt"),
        "{e}"
    );
    let lifted = [
        &QUICK[..],
        &[
            "--steps",
            "10",
            "--name",
            "eight",
            "--init-from",
            "out/seven.policy",
        ],
    ]
    .concat();
    ok(d, &lifted);
    let e = fails(
        d,
        &[
            "train",
            "--steps",
            "10",
            "--hasher",
            "bits7",
            "--init-from",
            "out/eight.policy",
        ],
    );
    assert!(
        e.contains("bits7") && e.contains("original") && e.contains("out/eight.policy"),
        "{e}"
    );

    let ckpt = std::fs::read(d.join("out/seven.ckpt")).unwrap();
    std::fs::write(d.join("cut.ckpt"), &ckpt[..ckpt.len() / 2]).unwrap();
    let e = fails(d, &["train", "--resume", "cut.ckpt"]);
    assert!(e.contains("cut.ckpt") && e.contains("truncated"), "{e}");
    let e = fails(d, &["train", "--resume", "out/seven.policy"]);
    assert!(e.contains("policy blob, not a checkpoint"), "{e}");
    let e = fails(
        d,
        &[
            "train",
            "--resume",
            "out/seven.ckpt",
            "--hasher",
            "original",
        ],
    );
    assert!(e.contains("--hasher cannot change"), "{e}");
    let e = fails(d, &["train", "--resume", "/no/such.ckpt"]);
    assert!(e.contains("/no/such.ckpt"), "{e}");
}

#[test]
fn an_output_folder_that_cannot_be_written_is_refused_before_the_first_step() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("file"), b"a file, not a folder").unwrap();
    // a billion steps: without the check they would all run first
    let out = host()
        .current_dir(dir.path())
        .args(["train", "--steps", "1000000000", "--out", "file/out"])
        .timeout(std::time::Duration::from_secs(60))
        .output()
        .unwrap();
    let e = String::from_utf8(out.stderr).unwrap();
    assert_eq!(out.status.code(), Some(1), "{e}");
    assert!(e.contains("cannot create folder file/out"), "{e}");
}
