//! # streaks-dataset
//!
//! The files of a rendered stereo sample and of a dataset of them, without the renderer (the
//! analysis and other readers use it on folders they did not render):
//!
//! - [`files`]: every file name, once, and [`files::SampleDir`], which names, reads and checks
//!   the files of a sample folder (a dataset's `samples/NNNNNN/` and a `streaks stereo`
//!   folder alike, also in the older pair layout);
//! - [`meta`]: a sample's `meta.json`, and its render seed;
//! - [`settings`]: the render settings a dataset's samples share ([`settings::Settings`]);
//! - [`outputs`]: the groups of files a dataset's samples keep (`--outputs`);
//! - [`layout`]: the dataset folder, `dataset.json` and the conventions it states, and its
//!   Middlebury-style sample folders;
//! - [`kitti`]: the KITTI 2015 view of a sample;
//! - [`sceneflow`]: the SceneFlow (FlyingThings3D) view of a sample;
//! - [`segmentation`]: the semantic and instance maps, the class table and the instance
//!   numbering (Cityscapes' label convention);
//! - [`manifest`]: reading `manifest.jsonl` back and checking files against it;
//! - [`lock`]: the advisory locks that make runs on one folder safe or refused;
//! - [`shard`]: `--shard K/N`;
//! - [`verify`]: checking a dataset's samples on disk and writing its manifest and splits, or
//!   checking its files against the manifest;
//! - `write` (feature `render`): writing a rendered pair into a sample folder, the one
//!   writer of a sample's images and ground truth;
//! - [`error`]: the crate's error type, [`DatasetError`].
#![deny(missing_docs)]

pub mod error;
pub mod files;
pub mod kitti;
pub mod layout;
pub mod lock;
pub mod manifest;
pub mod meta;
pub mod outputs;
pub mod sceneflow;
pub mod segmentation;
pub mod settings;
pub mod shard;
pub mod verify;
#[cfg(feature = "render")]
pub mod write;

pub use error::DatasetError;
pub use files::SampleDir;
