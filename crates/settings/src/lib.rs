//! # streaks-settings
//!
//! How to render: the sampling settings every image of a run shares, defined once.
//!
//! [`RenderSettings`] says how each pixel is estimated (samples, adaptive sampling, path
//! length, path regularisation) and nothing about which image: the size, the seed and the
//! layers are the renderer's per-image `streaks_render::integrator::RenderJob`, which nests
//! these settings; a stereo pair (`streaks_stereo::render::PairSettings`), a dataset
//! (`streaks_dataset::settings::Settings`) and a sample's `meta.json`
//! (`streaks_dataset::meta::RenderMeta`) nest the same type. So a setting is added,
//! documented and checked ([`RenderSettings::check`]) here once.
//!
//! The type is its own crate, without the renderer, because the readers of dataset files (the
//! `streaks-dataset` crate, and through it the analysis) do not link the renderer.
//!
//! Its serde form is the one `dataset.json` records (flattened into the file, in the field
//! order below); `meta.json` writes the same fields with the eyes' seeds among them.
#![deny(missing_docs)]

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// How each pixel of an image is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RenderSettings {
    /// Samples per pixel (the cap, with adaptive sampling); at least 1.
    pub spp: u32,
    /// Longest path, Mitsuba's `max_depth` (1 renders only emitters seen directly, 2 direct
    /// light, 3 one indirect bounce...; `u32::MAX`: no limit); at least 1. See
    /// the renderer's `integrator` module.
    pub max_depth: u32,
    /// Path regularisation (Cycles' "Filter Glossy"; biased, see the renderer's `integrator` module). A
    /// file written before the setting existed has none and was rendered without it: it reads
    /// as `false`.
    #[serde(default)]
    pub regularize: bool,
    /// Adaptive sampling: stop a tile of pixels once the estimated relative standard error of
    /// its pixels' mean luminance is below this (a positive, finite fraction such as 0.1);
    /// `None` takes `spp` samples everywhere (see the renderer's `integrator` module). A file written
    /// before the setting existed has none and was rendered at fixed spp: it reads as `None`.
    #[serde(default)]
    pub noise_target: Option<f32>,
}

/// A render setting out of its range: which setting ([`SettingsError::name`], as files
/// record it) and why ([`SettingsError::reason`]).
#[derive(Clone, Copy, Debug, PartialEq, Error)]
#[error("{} {}", self.name(), self.reason())]
pub enum SettingsError {
    /// `spp` is 0.
    Spp,
    /// `max_depth` is 0.
    MaxDepth,
    /// `noise_target` is not a positive, finite number.
    NoiseTarget(f32),
}

impl SettingsError {
    /// The setting's name, as `dataset.json` and `meta.json` record it (`spp`, `max_depth`,
    /// `noise_target`); a command line spells it with `-` for `_`.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Spp => "spp",
            Self::MaxDepth => "max_depth",
            Self::NoiseTarget(_) => "noise_target",
        }
    }

    /// Why the value is refused, as a sentence that follows the setting's name.
    pub fn reason(&self) -> String {
        match self {
            Self::Spp => "must be at least 1".into(),
            Self::MaxDepth => "must be at least 1 (1 renders only emitters seen directly)".into(),
            Self::NoiseTarget(rel) => format!(
                "must be a positive, finite relative standard error (such as 0.05), got {rel}"
            ),
        }
    }
}

impl RenderSettings {
    /// `spp` samples everywhere, paths of at most `max_depth` segments, no regularisation:
    /// the plain unbiased estimator.
    pub fn new(spp: u32, max_depth: u32) -> Self {
        Self {
            spp,
            max_depth,
            regularize: false,
            noise_target: None,
        }
    }

    /// Fails, naming the first setting out of its range: `spp` and `max_depth` must be at
    /// least 1, `noise_target` positive and finite ([`check_noise_target`]).
    pub fn check(&self) -> Result<(), SettingsError> {
        if self.spp == 0 {
            return Err(SettingsError::Spp);
        }
        if self.max_depth == 0 {
            return Err(SettingsError::MaxDepth);
        }
        if let Some(rel) = self.noise_target {
            check_noise_target(rel)?;
        }
        Ok(())
    }
}

/// Fails unless `rel` is a usable adaptive-sampling target: a positive, finite relative
/// standard error.
pub fn check_noise_target(rel: f32) -> Result<(), SettingsError> {
    if rel.is_finite() && rel > 0.0 {
        Ok(())
    } else {
        Err(SettingsError::NoiseTarget(rel))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_range_settings_are_named() {
        assert_eq!(RenderSettings::new(1, 1).check(), Ok(()));
        assert_eq!(RenderSettings::new(0, 8).check(), Err(SettingsError::Spp));
        assert_eq!(
            RenderSettings::new(4, 0).check(),
            Err(SettingsError::MaxDepth)
        );
        for rel in [0.0, -0.1, f32::NAN, f32::INFINITY] {
            let settings = RenderSettings {
                noise_target: Some(rel),
                ..RenderSettings::new(4, 8)
            };
            let err = settings.check().unwrap_err();
            assert_eq!(err.name(), "noise_target");
            assert!(
                err.to_string()
                    .starts_with("noise_target must be a positive"),
                "{err}"
            );
        }
        let adaptive = RenderSettings {
            noise_target: Some(0.05),
            ..RenderSettings::new(4, 8)
        };
        assert_eq!(adaptive.check(), Ok(()));
        assert_eq!(
            SettingsError::MaxDepth.to_string(),
            "max_depth must be at least 1 (1 renders only emitters seen directly)"
        );
    }

    /// The serde form: the fields in `dataset.json`'s order, a target written as its shortest
    /// decimal, and files from before `regularize` and `noise_target` existed read as off.
    #[test]
    fn serde_form_keeps_the_recorded_fields() {
        let settings = RenderSettings {
            regularize: true,
            noise_target: Some(0.1),
            ..RenderSettings::new(64, 8)
        };
        let text = serde_json::to_string(&settings).unwrap();
        assert_eq!(
            text,
            r#"{"spp":64,"max_depth":8,"regularize":true,"noise_target":0.1}"#
        );
        let back: RenderSettings = serde_json::from_str(&text).unwrap();
        assert_eq!(back, settings);
        let old: RenderSettings = serde_json::from_str(r#"{"spp":64,"max_depth":8}"#).unwrap();
        assert_eq!(old, RenderSettings::new(64, 8));
    }
}
