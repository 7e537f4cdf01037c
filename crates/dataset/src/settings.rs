//! How the samples of a dataset are rendered: one type, recorded once in `dataset.json`
//! (flattened, so its fields keep the names they always had there) and given to every sample.

use serde::{Deserialize, Serialize};

/// The render settings every sample of a dataset shares.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel per eye (the cap, with adaptive sampling).
    pub spp: u32,
    /// Longest path (Mitsuba's meaning).
    pub max_depth: u32,
    /// Path regularisation (`--no-regularize` turns it off). A `dataset.json` written before
    /// the field existed has none and was rendered without it: it reads as `false`.
    #[serde(default)]
    pub regularize: bool,
    /// Adaptive sampling's target (`--noise-target`; `None`: `spp` samples everywhere). A
    /// `dataset.json` written before the field existed has none and was rendered at fixed
    /// spp: it reads as `None`.
    #[serde(default)]
    pub noise_target: Option<f64>,
}
