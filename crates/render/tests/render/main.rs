//! The renderer's integration tests, in one test binary (one link of the renderer instead of
//! one per file): scenes with compressed and quantised geometry, hostile files, instancing,
//! and the image regression against stored references.

mod compressed;
mod hostile_files;
mod instancing;
mod regression;
