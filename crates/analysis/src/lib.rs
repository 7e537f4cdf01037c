//! # streaks-analysis
//!
//! What specular streaks do to stereo depth: the paper's virtual light column model and the
//! plots that show it. Works on geometry (the stereo crate's rig) and images (`streaks-image`:
//! grey images, regions, PFM and PNG files) only; it never depends on the renderer.
//!
//! - [`model`]: Eq. 2 and Eq. 4 in the road frame ([`model::ColumnModel`]: a light and a
//!   viewer; the locus of `L_virtual`, the proposition's invariance check) and the prediction
//!   per image row of a streak ([`model::streak_rows`]). Its cameras, their horizon, elevation
//!   angles and disparities in pixels and degrees are the stereo crate's
//!   ([`streaks_stereo::rig::RoadRig`], in `f64`), as are the report's: one camera model.
//! - [`centre`]: the streak-centre model: the brightest point of each row in each eye (the
//!   half vector nearest the normal) and its disparity, flat at the light's own disparity,
//!   beside Eq. 4 ([`centre::CentreModel`]).
//! - [`plot`]: line, scatter and arrow plots with labelled axes and legends, written
//!   atomically to PNG (plotters, with a font bundled in the crate).
//! - [`figures`]: the paper's figures made from the model (Fig. 4, Fig. 5).
//! - [`lk`]: the paper's per-row 1D Lucas-Kanade estimator, and the preparation of a rendered
//!   pair for it (fireflies removed, range log-compressed).
//! - [`detect`]: streaks, glows and lamps in the left image, by hand-built rules for 8-bit
//!   images; masks scored against the truth.
//! - [`streak_classifier`]: learned streak detection on linear luminance: per-pixel features
//!   and a trained classifier (the shipped one in `models/`), on [`gbdt`]'s gradient-boosted
//!   trees (training and inference) and [`filter`]'s sliding-window medians, means and maxima.
//! - [`detector`]: either detector ready to run on a loaded image, and its score over samples
//!   with known streaks (per sample, pooled, a point of the precision-recall curve).
//! - [`benchmark`]: an estimate scored by region (streak, road, off-road; the phantom-hole
//!   rate), pooled over samples; the LK streak disparity as a map; signed error maps.
//! - [`repair`]: streak-robust stereo without a road model: local stereo and appearance
//!   features, learned classifiers of fooled values and of road streaks (the shipped model
//!   in `models/`), the masking or repair of fooled values from the surface around them, a
//!   calibrated confidence map; [`repair::estimate`], the dense estimate with or without it.
//! - [`road_plane`]: whether the road is the plane `Y = 0` the analysis assumes, measured on
//!   a sample's ground-truth depth and road mask.
//! - [`sgm`]: dense semi-global matching, and its errors against a ground truth (bad-2.0).
//! - [`report`]: the per-streak analysis of a rendered or photographed pair (Fig. 6, Fig. 8):
//!   measured against predicted disparity per row, poles and road against their ground truth,
//!   the dense disparity scored on streak and other pixels, implied depths, plots and
//!   `report.json`. One file per stage under `report/`: `input.rs` (loading a pair),
//!   `stats.rs` (line fits, comparisons), `lights.rs` (matching streaks to lights), `targets.rs`
//!   (picking poles and road), `dense.rs` (the SGM point cloud and its score), `pipeline.rs`
//!   ([`report::analyze`]) and `output.rs` (plots, `report.json`, the console table); `mod.rs`
//!   holds the report's types.
//! - [`synth`]: synthetic pairs and streak images with known answers, for the tests and the
//!   benchmarks.
//!
//! ```
//! use glam::DVec3;
//! use streaks_analysis::model::ColumnModel;
//!
//! // The paper's Fig. 6 set-up: light 15 m ahead at 1.5 m, viewer at 1.5 m, 6.5 cm baseline.
//! let model = ColumnModel::new(DVec3::new(0.0, 1.5, 15.0), DVec3::new(0.0, 1.5, 0.0))?;
//! let locus = model.locus_profile(Some(4.0), 101, 0.065)?;
//! // The virtual column lies below the road, near the light's depth...
//! assert!(locus.iter().all(|p| p.reflection.virtual_light.y < 0.0));
//! // ...so its disparity barely changes along the streak (0.0078 degrees over 8 degrees).
//! let (near, far) = (locus[0], locus[100]);
//! assert!((near.elevation_deg - far.elevation_deg - 8.0).abs() < 1e-9);
//! assert!((near.disparity_deg - far.disparity_deg) < 0.008);
//! # Ok::<(), streaks_analysis::model::ModelError>(())
//! ```
#![deny(missing_docs)]

pub mod benchmark;
pub mod centre;
pub mod detect;
pub mod detector;
pub mod figures;
pub mod filter;
pub mod gbdt;
pub mod lk;
pub mod model;
pub mod plot;
pub mod repair;
pub mod report;
pub mod road_plane;
pub mod sgm;
pub mod streak_classifier;
pub mod synth;
