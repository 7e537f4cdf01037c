//! How the samples of a dataset are rendered: one type, recorded once in `dataset.json`
//! (flattened, so its fields keep the names they always had there) and given to every sample.

use serde::{Deserialize, Serialize};
use streaks_settings::RenderSettings;

/// The image size and render settings every sample of a dataset shares.
///
/// In `dataset.json` the fields are the file's own, in this order: `width`, `height`, then the
/// render settings' (`spp`, `max_depth`, `regularize`, `noise_target`). A `dataset.json`
/// written before `regularize` or `noise_target` existed has none and was rendered without
/// path regularisation or at fixed spp: it reads so ([`RenderSettings`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// How each eye of each sample is sampled (`--spp`, `--max-depth`, `--no-regularize`,
    /// `--noise-target`).
    #[serde(flatten)]
    pub render: RenderSettings,
}
