//! (skeleton: sampling, filled in by its owner)
