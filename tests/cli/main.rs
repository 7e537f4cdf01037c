//! End-to-end tests: the real `streaks` executable, run in a fresh temporary folder per test,
//! on tiny scenes written by the tests and on the shipped scenes. One test binary (ripgrep's
//! habit), one module per group of subcommands.

mod analyze;
mod benchmark;
mod camera;
mod common;
mod dataset;
mod detect;
mod khronos;
mod measure;
mod render;
mod repair;
mod sensor;
mod special_files;
mod stereo;
