//! (skeleton: film, filled in by its owner)
