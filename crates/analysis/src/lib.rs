//! streaks-analysis (skeleton).
#![deny(missing_docs)]

pub mod detect;
pub mod lk;
pub mod sgm;
pub mod synth;
