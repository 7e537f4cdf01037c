//! A FIFO or a device named where a text file belongs (a generator config, a rig, a
//! classifier) is a prompt error naming it, not a hang or an endless read.

use crate::common::TestDir;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Runs `streaks ARGS` in `t`, killed after 20 s (a regression fails instead of hanging);
/// asserts that it failed within 10 s and that its error names `needle`.
fn fails_promptly(t: &TestDir, args: &[&str], needle: &str) {
    let start = Instant::now();
    let mut child = Command::new(env!("CARGO_BIN_EXE_streaks"))
        .args(args)
        .current_dir(t.path())
        .env("CI", "true")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot run the streaks executable");
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(20) {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("streaks {args:?} still ran after 20 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let elapsed = start.elapsed();
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    assert!(!status.success(), "streaks {args:?} succeeded");
    assert!(
        elapsed < Duration::from_secs(10),
        "{args:?} took {elapsed:?}"
    );
    assert!(err.contains(needle), "{args:?}: no {needle:?} in: {err}");
}

#[test]
fn fifos_and_devices_as_text_files_are_refused_promptly() {
    let t = TestDir::new();
    let fifo = t.join("pipe");
    let made = Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo failed");
    image::RgbImage::new(16, 8)
        .save(t.join("road.png"))
        .unwrap();
    for special in ["pipe", "/dev/zero"] {
        fails_promptly(
            &t,
            &[
                "dataset", "generate", "-o", "ds", "--count", "1", "--width", "16", "--height",
                "8", "--spp", "1", "--config", special,
            ],
            special,
        );
        fails_promptly(
            &t,
            &[
                "texture-map",
                "road.png",
                "--rig",
                special,
                "--x-range",
                "-3,3",
                "--z-range",
                "1,8",
                "--resolution",
                "0.5",
                "-o",
                "map.png",
            ],
            special,
        );
        fails_promptly(
            &t,
            &["detect", "road.png", "--model", special, "-o", "mask.png"],
            special,
        );
    }
}
