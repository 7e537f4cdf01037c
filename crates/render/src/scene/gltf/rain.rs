//! The scene's rain, from `scenes[i].extras.streaks.rain`: `{"rate_mm_h": R, "seed": n,
//! "radius": m}` (`seed` optional, 0; `radius` optional, [`DEFAULT_RADIUS`] metres). What the
//! values mean and how drops are made from them: [`crate::rain`].

use super::Loader;
use crate::rain::{RainParams, DEFAULT_RADIUS};
use crate::scene::SceneError;
use serde::Deserialize;

/// `extras.streaks.rain` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RainExtras {
    /// Rain rate, mm/h.
    rate_mm_h: f32,
    /// Seed of the drops' placement.
    seed: Option<u64>,
    /// How far from the camera drops are placed, metres.
    radius: Option<f32>,
}

impl Loader<'_> {
    /// The rain `scene`'s extras ask for, if any.
    pub(super) fn rain(&self, scene: &gltf::Scene) -> Result<Option<RainParams>, SceneError> {
        let element = format!("scene {}, extras.streaks.rain", scene.index());
        let Some(raw) = scene.extras() else {
            return Ok(None);
        };
        let extras: serde_json::Value = serde_json::from_str(raw.get())
            .map_err(|e| self.bad(&element, format!("extras: {e}")))?;
        let Some(value) = extras.pointer("/streaks/rain") else {
            return Ok(None);
        };
        let rain: RainExtras =
            serde_json::from_value(value.clone()).map_err(|e| self.bad(&element, e.to_string()))?;
        let params = RainParams {
            rate_mm_h: rain.rate_mm_h,
            seed: rain.seed.unwrap_or(0),
            radius: rain.radius.unwrap_or(DEFAULT_RADIUS),
        };
        params
            .check()
            .map_err(|(key, reason)| self.bad(format!("{element}.{key}"), reason))?;
        Ok(Some(params))
    }
}
