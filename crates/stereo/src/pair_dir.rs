//! The files of a pair folder (`streaks stereo -o DIR`), named once here for the writer
//! ([`crate::render::write_pair`], [`crate::pair::write_pair_views`]) and every reader (the
//! analysis, `streaks prepare`, the tests).
//!
//! Per eye (`left`, `right`): `EYE.exr` (linear, with the depth, normal and specular layers),
//! `EYE.png` (8-bit sRGB), `disparity_EYE.pfm` and `depth_EYE.pfm` (ground truth, Middlebury
//! PFM), `streak_mask_EYE.png` (0/255), `road_mask_EYE.png` (0/255, when the scene flags a
//! road material). For the pair: `side_by_side.png`, `anaglyph.png` and
//! `rig.json`.

use crate::rig::Eye;
use std::path::{Path, PathBuf};

/// A pair folder: the paths of its files.
#[derive(Clone, Copy, Debug)]
pub struct PairDir<'a> {
    dir: &'a Path,
}

impl<'a> PairDir<'a> {
    /// The pair folder `dir`.
    pub fn new(dir: &'a Path) -> Self {
        Self { dir }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        self.dir
    }

    /// `EYE.exr`: the linear image with its layers.
    pub fn exr(&self, eye: Eye) -> PathBuf {
        self.dir.join(format!("{}.exr", eye.name()))
    }

    /// `EYE.png`: the 8-bit sRGB image.
    pub fn png(&self, eye: Eye) -> PathBuf {
        self.dir.join(format!("{}.png", eye.name()))
    }

    /// The eye's image to measure: `EYE.exr` if it exists, else `EYE.png`.
    pub fn image(&self, eye: Eye) -> PathBuf {
        let exr = self.exr(eye);
        if exr.exists() {
            exr
        } else {
            self.png(eye)
        }
    }

    /// `disparity_EYE.pfm`: ground-truth disparity.
    pub fn disparity(&self, eye: Eye) -> PathBuf {
        self.dir.join(format!("disparity_{}.pfm", eye.name()))
    }

    /// `depth_EYE.pfm`: ground-truth depth.
    pub fn depth(&self, eye: Eye) -> PathBuf {
        self.dir.join(format!("depth_{}.pfm", eye.name()))
    }

    /// `streak_mask_EYE.png`: the renderer's streak mask.
    pub fn streak_mask(&self, eye: Eye) -> PathBuf {
        self.dir.join(format!("streak_mask_{}.png", eye.name()))
    }

    /// `road_mask_EYE.png`: the pixels whose first hit is the road surface (0/255; written
    /// only when the scene flags a road material).
    pub fn road_mask(&self, eye: Eye) -> PathBuf {
        self.dir.join(format!("road_mask_{}.png", eye.name()))
    }

    /// `side_by_side.png`.
    pub fn side_by_side(&self) -> PathBuf {
        self.dir.join("side_by_side.png")
    }

    /// `anaglyph.png`.
    pub fn anaglyph(&self) -> PathBuf {
        self.dir.join("anaglyph.png")
    }

    /// `rig.json`.
    pub fn rig(&self) -> PathBuf {
        self.dir.join("rig.json")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_follow_the_pair_folder_layout() {
        let dir = tempfile::tempdir().unwrap();
        let p = PairDir::new(dir.path());
        let name = |q: PathBuf| q.file_name().unwrap().to_string_lossy().into_owned();
        assert_eq!(name(p.disparity(Eye::Left)), "disparity_left.pfm");
        assert_eq!(name(p.streak_mask(Eye::Right)), "streak_mask_right.png");
        assert_eq!(name(p.road_mask(Eye::Left)), "road_mask_left.png");
        assert_eq!(name(p.rig()), "rig.json");
        // The image to measure: the EXR when there is one.
        assert_eq!(name(p.image(Eye::Left)), "left.png");
        std::fs::write(p.exr(Eye::Left), b"").unwrap();
        assert_eq!(name(p.image(Eye::Left)), "left.exr");
    }
}
