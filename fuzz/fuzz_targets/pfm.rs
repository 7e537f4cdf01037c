//! The `pfm` target for cargo-fuzz: `cargo +nightly fuzz run pfm`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = streaks_fuzz::targets::pfm(data);
});
