//! (skeleton: output, filled in by its owner)
