//! Render regression tests (see `streaks_render::regression`): each shipped scene of
//! `REGRESSION_CASES` rendered at 128 samples per pixel against its stored mean and variance,
//! by a Z-test of 4x4-pixel block means with the Sidak correction.

use streaks_render::regression::{mean_radiance, Reference, RegressionCase, REGRESSION_CASES};

/// Samples per pixel of the renders under test, and their seed (the references use
/// `0..REFERENCE_RENDERS`).
const SPP: u32 = 128;
const SEED: u32 = 1_000_003;
/// Block size of the test (see `Reference::z_test`): block means are nearly normal where
/// single pixels of a night street are not (rare bright paths).
const BLOCK: u32 = 4;
/// Significance of each case's test, before the Sidak correction over its pixels.
const ALPHA: f64 = 0.01;

fn check(case: &RegressionCase) {
    let reference = Reference::load(&case.reference_path()).unwrap_or_else(|e| {
        panic!(
            "{}: no reference ({e}); make it with `cargo run --release -p streaks-render \
             --example regression_references {}`",
            case.scene, case.scene
        )
    });
    let scene = case.load().unwrap();
    let image = case.render(&scene, SPP, SEED).unwrap();
    let test = reference.z_test(&image, SPP, BLOCK, ALPHA);
    assert!(
        test.passed,
        "{} ({}x{}, {SPP} spp): {test}; mean radiance {:.6e} against {:.6e}",
        case.scene,
        case.width,
        case.height,
        mean_radiance(&image),
        mean_radiance(&reference.mean)
    );
}

#[test]
fn crosscheck_matches_its_reference() {
    check(&REGRESSION_CASES[0]);
}

#[test]
fn rainy_street_small_matches_its_reference() {
    check(&REGRESSION_CASES[1]);
}

#[test]
fn paper_ward_plane_matches_its_reference() {
    check(&REGRESSION_CASES[2]);
}

#[test]
fn paper_blinn_phong_plane_matches_its_reference() {
    check(&REGRESSION_CASES[3]);
}

/// The test can fail: the same scenes with one bounce less (an ordinary light-transport bug)
/// or a 3% brighter image are caught.
#[test]
fn a_change_in_light_transport_fails() {
    let case = &REGRESSION_CASES[0];
    let reference = Reference::load(&case.reference_path()).unwrap();
    let scene = case.load().unwrap();
    let short = RegressionCase {
        max_depth: case.max_depth - 1,
        ..*case
    };
    let image = short.render(&scene, SPP, SEED).unwrap();
    let test = reference.z_test(&image, SPP, BLOCK, ALPHA);
    assert!(!test.passed, "max depth {}: {test}", short.max_depth);
    let mut brighter = case.render(&scene, SPP, SEED).unwrap();
    for p in &mut brighter.pixels {
        *p *= 1.03;
    }
    let test = reference.z_test(&brighter, SPP, BLOCK, ALPHA);
    assert!(!test.passed, "3% brighter: {test}");
}
