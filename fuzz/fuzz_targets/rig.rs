//! The `rig` target for cargo-fuzz: `cargo +nightly fuzz run rig`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = streaks_fuzz::targets::rig(data);
});
