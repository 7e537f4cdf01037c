//! # streaks-stereo
//!
//! Rectified stereo for the streaks project: the rig geometry, ground truth, viewing aids and
//! the ground-plane texture map. Everything but [`render`] works without the renderer (build
//! with `--no-default-features`), so the analysis can use it on photographs. Images, PFM maps
//! and atomic writes are the `streaks-image` crate's.
//!
//! - [`rig`]: the camera model. [`rig::Rig`] (intrinsics, baseline, pose), its eyes
//!   ([`rig::EyeCamera`]: projection, back-projection), disparity <-> depth (Eq. 5) and the road
//!   frame; and the same rig in `f64` road coordinates ([`rig::RoadRig`]: projection, ground
//!   points, horizon, elevation, disparity in pixels and the one definition of angular
//!   disparity), which the analysis crate uses for all its angles.
//! - [`calib`]: `calib.txt` in the Middlebury 2014 format ([`calib::MiddleburyCalib`]).
//! - [`rigfile`]: `rig.json` ([`rigfile::RigFile`]), with the scene's lights in world and road
//!   coordinates.
//! - [`pair`]: side-by-side and anaglyph views; the paper's Fig. 7 treatment of photographs.
//! - [`streak_mask`]: which pixels are specular streaks, from the renderer's specular layer.
//! - [`texture_map`]: the paper's Fig. 3 ground-plane texture map.
//! - [`flow`]: exact optical flow and disparity change of the left eye between two frames.
//! - [`occlusion`]: which pixels of each eye show a point the other eye does not see.
//! - [`font`]: the bundled plot font (plotters + `ab_glyph`, no system fonts).
//! - [`render`] (feature `render`): rendering a pair with ground-truth disparity and depth.
//!
//! ```
//! use streaks_stereo::rig::{Eye, Intrinsics, Rig};
//! use glam::{Affine3A, Vec2, Vec3};
//!
//! let rig = Rig::new(
//!     Intrinsics::new(640, 480, 500.0)?,
//!     0.065,
//!     Affine3A::from_translation(Vec3::new(0.0, 1.5, 0.0)),
//! )?;
//! let p = rig.eye(Eye::Left).back_project(Vec2::new(100.0, 300.0), 15.0);
//! let d = rig.eye(Eye::Left).project(p).unwrap().x - rig.eye(Eye::Right).project(p).unwrap().x;
//! assert!((d - rig.disparity_px(15.0)).abs() < 1e-3); // f b / Z
//! # Ok::<(), streaks_stereo::error::StereoError>(())
//! ```
#![deny(missing_docs)]

pub mod calib;
pub mod error;
pub mod flow;
pub mod font;
pub mod occlusion;
pub mod pair;
#[cfg(feature = "render")]
pub mod render;
pub mod rig;
pub mod rigfile;
pub mod streak_mask;
pub mod texture_map;
