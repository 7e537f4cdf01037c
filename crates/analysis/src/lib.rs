//! streaks-analysis (skeleton).
#![deny(missing_docs)]
