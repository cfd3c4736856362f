//! Each command's help lists only the options it uses, with one number
//! style for step counts: `host search` and `host policy gap` take a
//! training config's flags but hide (and refuse) those only training uses,
//! and say what `--out` and `--steps` mean for them.

use std::process::Command;

const HOST: &str = env!("CARGO_BIN_EXE_host");

fn help(command: &[&str]) -> String {
    let out = Command::new(HOST)
        .args(command)
        .arg("--help")
        .output()
        .unwrap();
    assert!(out.status.success(), "{command:?} --help");
    String::from_utf8(out.stdout).unwrap()
}

/// Whether the help lists `flag` as an option.
fn lists(help: &str, flag: &str) -> bool {
    help.lines()
        .any(|l| l.trim_start().starts_with(&format!("{flag} ")))
}

fn refused(args: &[&str]) -> String {
    let out = Command::new(HOST).args(args).output().unwrap();
    assert!(!out.status.success(), "{args:?} was accepted");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn search_and_policy_gap_list_only_the_training_options_they_use() {
    let search = help(&["search"]);
    for unused in [
        "--steps",
        "--checkpoint-every",
        "--select-every",
        "--select-steps",
    ] {
        assert!(!lists(&search, unused), "host search lists {unused}");
    }
    assert!(search.contains("<name>.search.json"), "{search}");
    assert!(!search.contains("<name>.ckpt"), "{search}");
    let e = refused(&["search", "--steps", "5"]);
    assert!(e.contains("host search does not use --steps"), "{e}");

    let gap = help(&["policy", "gap"]);
    for unused in ["--seed", "--out", "--name", "--checkpoint-every"] {
        assert!(!lists(&gap, unused), "host policy gap lists {unused}");
    }
    assert!(lists(&gap, "--seeds"), "{gap}");
    assert!(!gap.contains("when resuming"), "{gap}");
    let e = refused(&[
        "policy", "gap", "--label", "x", "--seeds", "1", "--json", "x.json", "--seed", "3",
    ]);
    assert!(e.contains("host policy gap does not use --seed"), "{e}");
}

#[test]
fn step_counts_are_written_one_way_and_run_and_render_default_alike() {
    for command in [
        &["train"][..],
        &["run"],
        &["render"],
        &["bench"],
        &["policy", "gap"],
    ] {
        let text = help(command);
        for line in text.lines().filter(|l| l.contains("[default: ")) {
            let default = line.split("[default: ").nth(1).unwrap();
            let digits = default.chars().take_while(|c| c.is_ascii_digit()).count();
            assert!(
                digits < 5,
                "{command:?}: a count without thousands separators: {line}"
            );
        }
    }
    for command in ["run", "render"] {
        let text = help(&[command]);
        let steps = text
            .lines()
            .skip_while(|l| !l.trim_start().starts_with("--steps "))
            .take(3)
            .collect::<String>();
        assert!(steps.contains("[default: 200,000]"), "{command}: {steps}");
    }
}
