//! (skeleton: integrator, filled in by its owner)
