//! `--outputs`: the groups of files a dataset's samples keep, so that a user writes only the
//! files they need. `calib.txt` and `meta.json` are always written (every reader of a sample
//! needs them); the KITTI and SceneFlow views are made from the sample's images, ground truth
//! and segmentation before the groups not chosen are removed.

use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;

/// One group of a sample's files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Output {
    /// `im0.png`, `im1.png`: the 8-bit images.
    Images,
    /// `im0_16.png`, `im1_16.png`: the same images at 16 bits (not kept by default).
    Images16,
    /// `im0.exr`, `im1.exr`: the linear renders with their layers.
    Exr,
    /// `disp0/1.pfm`, `depth0/1.pfm`, `occ0/1.png`: the ground truth.
    Gt,
    /// `streaks0.png`, `road0.png`, `rain0/1.png`, `fog0/1.pfm`: the masks.
    Masks,
    /// `semantic0/1.png`, `instance0/1.png`: the segmentation maps.
    Segmentation,
    /// `flow0.png`, `flow0.pfm`, `dispchange0.pfm`, `flowmask0.png`: the flow to the next
    /// frame.
    Flow,
    /// `scene.gltf`, `scene.bin`, `scene_*.png`: the scene.
    Scene,
    /// The KITTI 2015 view (`kitti/training/...`).
    Kitti,
    /// The SceneFlow view (`SceneFlow/FlyingThings3D/...`).
    Sceneflow,
}

impl Output {
    /// Every group, in the order of `dataset.json`.
    pub const ALL: [Output; 10] = [
        Output::Images,
        Output::Images16,
        Output::Exr,
        Output::Gt,
        Output::Masks,
        Output::Segmentation,
        Output::Flow,
        Output::Scene,
        Output::Kitti,
        Output::Sceneflow,
    ];

    /// The group's name (`--outputs`, `dataset.json`).
    pub fn name(self) -> &'static str {
        match self {
            Output::Images => "images",
            Output::Images16 => "images16",
            Output::Exr => "exr",
            Output::Gt => "gt",
            Output::Masks => "masks",
            Output::Segmentation => "segmentation",
            Output::Flow => "flow",
            Output::Scene => "scene",
            Output::Kitti => "kitti",
            Output::Sceneflow => "sceneflow",
        }
    }

    /// The group of the sample-folder file `name`; `None` for `calib.txt` and `meta.json`,
    /// which every sample keeps.
    pub fn of_file(name: &str) -> Option<Output> {
        if name.starts_with("im") && name.ends_with("_16.png") {
            return Some(Output::Images16);
        }
        let stem = name.split('.').next().unwrap_or(name);
        let base = stem.trim_end_matches(['0', '1']);
        Some(match (base, name.rsplit('.').next().unwrap_or("")) {
            ("calib" | "meta", _) => return None,
            ("im", "png") => Output::Images,
            ("im", _) => Output::Exr,
            ("disp" | "depth" | "occ", _) => Output::Gt,
            ("streaks" | "road" | "rain" | "fog", _) => Output::Masks,
            ("semantic" | "instance", _) => Output::Segmentation,
            ("flow" | "dispchange" | "flowmask", _) => Output::Flow,
            _ => Output::Scene,
        })
    }
}

impl std::str::FromStr for Output {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Output::ALL
            .into_iter()
            .find(|o| o.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Output::ALL.iter().map(|o| o.name()).collect();
                format!("unknown output group {s:?}: expected {}", names.join(", "))
            })
    }
}

/// The groups a dataset's samples keep (`dataset.json`'s `outputs`, sorted); every group by
/// default, and for a `dataset.json` written before the setting existed.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Outputs(pub BTreeSet<Output>);

impl Default for Outputs {
    /// Every group but [`Output::Images16`] (which doubles the images' size for a precision
    /// most readers drop): what a dataset keeps without `--outputs`, and what one written
    /// before the setting existed kept.
    fn default() -> Self {
        Self(
            Output::ALL
                .into_iter()
                .filter(|&o| o != Output::Images16)
                .collect(),
        )
    }
}

impl Outputs {
    /// The groups as `--outputs` takes them (`images,exr,...`).
    pub fn to_flag(&self) -> String {
        let names: Vec<&str> = self.0.iter().map(|o| o.name()).collect();
        names.join(",")
    }

    /// Whether the group `output` is kept.
    pub fn has(&self, output: Output) -> bool {
        self.0.contains(&output)
    }

    /// Whether a sample keeps its folder's file `name`.
    pub fn keeps(&self, name: &str) -> bool {
        Output::of_file(name).is_none_or(|o| self.has(o))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::files::{FLOW_FILES, SAMPLE_FILES, SCENE_BIN, SCENE_GLTF};

    #[test]
    fn every_file_has_its_group() {
        let group = |f: &str| Output::of_file(f);
        assert_eq!(group("im0.png"), Some(Output::Images));
        assert_eq!(group("im1_16.png"), Some(Output::Images16));
        assert!(!Outputs::default().has(Output::Images16));
        assert!(Outputs::default().has(Output::Images));
        assert_eq!(group("im1.exr"), Some(Output::Exr));
        for f in [
            "disp0.pfm",
            "disp1.pfm",
            "depth1.pfm",
            "occ0.png",
            "occ1.png",
        ] {
            assert_eq!(group(f), Some(Output::Gt), "{f}");
        }
        for f in ["streaks0.png", "road0.png", "rain1.png", "fog0.pfm"] {
            assert_eq!(group(f), Some(Output::Masks), "{f}");
        }
        for f in ["semantic0.png", "instance1.png"] {
            assert_eq!(group(f), Some(Output::Segmentation), "{f}");
        }
        for f in FLOW_FILES {
            assert_eq!(group(f), Some(Output::Flow), "{f}");
        }
        for f in [SCENE_GLTF, SCENE_BIN, "scene_3.png"] {
            assert_eq!(group(f), Some(Output::Scene), "{f}");
        }
        assert_eq!(group("calib.txt"), None);
        assert_eq!(group("meta.json"), None);
        let images = Outputs([Output::Exr, Output::Images].into_iter().collect());
        let kept: Vec<&str> = SAMPLE_FILES
            .into_iter()
            .filter(|f| images.keeps(f))
            .collect();
        let expected = [
            "calib.txt",
            "im0.exr",
            "im0.png",
            "im1.exr",
            "im1.png",
            "meta.json",
        ];
        assert_eq!(kept, expected);
        assert_eq!(
            serde_json::to_string(&images).unwrap(),
            r#"["images","exr"]"#.to_owned()
        );
        for o in Output::ALL {
            assert_eq!(o.name().parse::<Output>(), Ok(o));
            assert_eq!(serde_json::to_value(o).unwrap(), o.name());
        }
        assert!("png"
            .parse::<Output>()
            .unwrap_err()
            .contains("images, images16, exr"));
    }
}
