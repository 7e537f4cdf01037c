//! The `glb` target for cargo-fuzz: `cargo +nightly fuzz run glb`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = streaks_fuzz::targets::glb(data);
});
