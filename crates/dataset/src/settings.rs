//! How the samples of a dataset are rendered: one type, recorded once in `dataset.json`
//! (flattened, so its fields keep the names they always had there) and given to every sample.

use crate::outputs::Outputs;
use serde::{Deserialize, Serialize};
use streaks_settings::RenderSettings;

/// The image size and render settings every sample of a dataset shares.
///
/// In `dataset.json` the fields are the file's own, in this order: `width`, `height`, then the
/// render settings' (`spp`, `max_depth`, `regularize`, `noise_target`), then `denoise`,
/// `keep_raw` and `outputs`. A `dataset.json` written before `regularize`, `noise_target` or `denoise`
/// existed has none and was rendered without path regularisation, at fixed spp or without
/// denoising: it reads so ([`RenderSettings`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// How each eye of each sample is sampled (`--spp`, `--max-depth`, `--no-regularize`,
    /// `--noise-target`).
    #[serde(flatten)]
    pub render: RenderSettings,
    /// Whether each eye's image is denoised (Intel Open Image Denoise; ground truth, masks
    /// and the specular layer never are).
    #[serde(default)]
    pub denoise: bool,
    /// Whether a denoised sample's EXR keeps the render before denoising (its `raw` layer).
    #[serde(default)]
    pub keep_raw: bool,
    /// The groups of files each sample keeps (`--outputs`; all of them in a `dataset.json`
    /// written before the setting existed).
    #[serde(default)]
    pub outputs: Outputs,
}
