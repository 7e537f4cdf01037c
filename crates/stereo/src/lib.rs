//! streaks-stereo (skeleton).
#![deny(missing_docs)]
