//! The BVH (INTERFACE SKELETON, filled in by the scene-loading work): the only module that
//! imports obvhs.

/// An obvhs CWBVH over the scene's triangles.
#[derive(Debug)]
pub struct Accel {}
