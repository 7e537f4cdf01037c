//! Every input of `fuzz/corpus/` and `fuzz/regressions/` goes through its target without a
//! panic, an abort, a hang or an allocation bomb: the stable runner, replaying only (no
//! mutation), as CI runs it before fuzzing.

use std::process::Command;

/// Runs the runner on `targets` with no mutation time; fails with its output unless it found
/// nothing.
fn replay(targets: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_streaks-fuzz"))
        .args(targets)
        .args(["--seconds", "0", "--jobs", "2"])
        .output()
        .expect("cannot run streaks-fuzz");
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_readers_take_their_corpus_and_regressions() {
    let names = streaks_fuzz::targets::TARGETS
        .iter()
        .map(|t| t.name)
        .filter(|&n| n != "dataset");
    replay(&names.collect::<Vec<_>>());
}

/// The dataset target runs the `streaks` binary, which `cargo test --workspace` builds beside
/// this package's (`cargo test -p streaks-fuzz` alone does not: then this test says so and
/// passes).
#[test]
fn the_dataset_index_takes_its_corpus_and_regressions() {
    let runner = std::path::Path::new(env!("CARGO_BIN_EXE_streaks-fuzz"));
    if std::env::var_os("STREAKS").is_none() && !runner.with_file_name("streaks").is_file() {
        eprintln!(
            "no streaks binary beside {}: not replayed",
            runner.display()
        );
        return;
    }
    replay(&["dataset"]);
}
