//! `rig.json`: the rig (intrinsics, baseline, poses), its road frame and the scene's lights, in
//! world and road coordinates, so the analysis can run on a rendered pair without the scene.
//!
//! Poses are written as a position and the three local axes in world space (the columns of the
//! rotation); an eye looks along `-z_axis`. Road coordinates use the left-handed road frame of
//! [`crate::rig`] (X right, Y up, Z forward). Reading checks that the file is consistent: a
//! rigid pose, a principal point at the image centre, eyes where the baseline puts them.

use crate::error::StereoError;
use crate::rig::{Eye, Intrinsics, Rig, RoadFrame};
use glam::{Affine3A, Mat3A, Vec3, Vec3A};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A pose: position and local axes in world space.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    /// Origin in world space (metres).
    pub position: [f32; 3],
    /// Local +X (right) in world space.
    pub x_axis: [f32; 3],
    /// Local +Y (up) in world space.
    pub y_axis: [f32; 3],
    /// Local +Z in world space (the camera looks along -Z).
    pub z_axis: [f32; 3],
}

impl PoseRecord {
    /// The record of a transform.
    pub fn from_affine(a: &Affine3A) -> Self {
        Self {
            position: Vec3::from(a.translation).into(),
            x_axis: Vec3::from(a.matrix3.x_axis).into(),
            y_axis: Vec3::from(a.matrix3.y_axis).into(),
            z_axis: Vec3::from(a.matrix3.z_axis).into(),
        }
    }

    /// The transform it records.
    pub fn to_affine(&self) -> Affine3A {
        Affine3A {
            matrix3: Mat3A::from_cols(
                Vec3A::from(self.x_axis),
                Vec3A::from(self.y_axis),
                Vec3A::from(self.z_axis),
            ),
            translation: Vec3A::from(self.position),
        }
    }
}

/// The shared intrinsics.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IntrinsicsRecord {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Focal length in pixels.
    pub focal_px: f32,
    /// Principal point (always the image centre; written for readers of the file).
    pub principal_point: [f32; 2],
    /// Vertical field of view in degrees (derived; written for readers of the file).
    pub yfov_deg: f32,
}

/// The road frame's origin and axes in world space.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoadFrameRecord {
    /// The road point below the rig centre.
    pub origin: [f32; 3],
    /// Road +X (camera right) in world space.
    pub x_axis: [f32; 3],
    /// Road +Y (up) in world space.
    pub y_axis: [f32; 3],
    /// Road +Z (camera forward on the road) in world space.
    pub z_axis: [f32; 3],
    /// Always `"left"`: X right, Y up, Z forward.
    pub handedness: String,
}

/// A point given in both frames.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Placed {
    /// World coordinates.
    pub world: [f32; 3],
    /// Road coordinates (absent when the rig has no road frame).
    pub road: Option<[f32; 3]>,
}

impl Placed {
    /// A world point and, if there is a road frame, its road coordinates.
    pub fn point(p: Vec3, road: Option<&RoadFrame>) -> Self {
        Self {
            world: p.into(),
            road: road.map(|r| r.road_from_world_point(p).into()),
        }
    }

    /// A world direction and, if there is a road frame, its road components.
    pub fn vector(v: Vec3, road: Option<&RoadFrame>) -> Self {
        Self {
            world: v.into(),
            road: road.map(|r| r.road_from_world_vector(v).into()),
        }
    }
}

/// A light of the scene, as the analysis needs it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum LightRecord {
    /// A point light.
    Point {
        /// Position.
        position: Placed,
        /// Radiant intensity (W/sr), linear RGB.
        intensity: [f32; 3],
        /// glTF range, if any.
        range: Option<f32>,
    },
    /// A spot light.
    Spot {
        /// Position.
        position: Placed,
        /// Unit direction it points along.
        direction: Placed,
        /// Radiant intensity on the axis (W/sr).
        intensity: [f32; 3],
        /// cos(inner cone angle).
        cos_inner: f32,
        /// cos(outer cone angle).
        cos_outer: f32,
        /// glTF range, if any.
        range: Option<f32>,
    },
    /// A directional light.
    Directional {
        /// Unit direction the light travels along.
        direction: Placed,
        /// Irradiance (W/m^2).
        irradiance: [f32; 3],
    },
    /// One of the renderer's emitter meshes: connected emissive triangles of one material (a
    /// lamp).
    Emissive {
        /// Centre of the emitter's bounding sphere (the centre of its vertices' bounding box),
        /// the point the renderer's light choice aims at.
        centroid: Placed,
        /// Total area (m^2).
        area: f32,
        /// Number of triangles.
        triangles: usize,
        /// Emitted radiance of the material (its factor, without a texture).
        radiance: [f32; 3],
        /// Material name.
        material: String,
    },
}

/// The contents of `rig.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RigFile {
    /// Baseline in metres.
    pub baseline: f32,
    /// The shared intrinsics.
    pub intrinsics: IntrinsicsRecord,
    /// The rig centre's pose.
    pub world_from_rig: PoseRecord,
    /// The left eye's pose (derived).
    pub left: PoseRecord,
    /// The right eye's pose (derived).
    pub right: PoseRecord,
    /// Height of the rig centre above the road (derived).
    pub rig_height: f32,
    /// The road frame, absent when the camera looks straight up or down.
    pub road_frame: Option<RoadFrameRecord>,
    /// The scene's lights.
    pub lights: Vec<LightRecord>,
}

impl RigFile {
    /// The record of `rig` with the given lights.
    pub fn new(rig: &Rig, lights: Vec<LightRecord>) -> Self {
        let i = rig.intrinsics();
        let pp = i.principal_point();
        Self {
            baseline: rig.baseline(),
            intrinsics: IntrinsicsRecord {
                width: i.width(),
                height: i.height(),
                focal_px: i.focal_px(),
                principal_point: [pp.x, pp.y],
                yfov_deg: i.yfov().to_degrees(),
            },
            world_from_rig: PoseRecord::from_affine(&rig.world_from_rig()),
            left: PoseRecord::from_affine(&rig.world_from_eye(Eye::Left)),
            right: PoseRecord::from_affine(&rig.world_from_eye(Eye::Right)),
            rig_height: rig.height(),
            road_frame: rig.road_frame().ok().map(|r| RoadFrameRecord {
                origin: r.origin.into(),
                x_axis: r.x_axis.into(),
                y_axis: r.y_axis.into(),
                z_axis: r.z_axis.into(),
                handedness: "left".into(),
            }),
            lights,
        }
    }

    /// The rig it describes, checked for consistency.
    pub fn rig(&self) -> Result<Rig, StereoError> {
        let ir = &self.intrinsics;
        let intr = Intrinsics::new(ir.width, ir.height, ir.focal_px)?;
        let pp = intr.principal_point();
        if (pp.x - ir.principal_point[0]).abs() > 1e-3
            || (pp.y - ir.principal_point[1]).abs() > 1e-3
        {
            return Err(StereoError::Intrinsics(format!(
                "principal point {:?} is not the image centre {pp}",
                ir.principal_point
            )));
        }
        let rig = Rig::new(intr, self.baseline, self.world_from_rig.to_affine())?;
        for (eye, rec) in [(Eye::Left, &self.left), (Eye::Right, &self.right)] {
            let expect = rig.world_from_eye(eye).translation;
            if (Vec3::from(expect) - Vec3::from(rec.position)).length() > 1e-4 {
                return Err(StereoError::Pose(format!(
                    "the {eye} eye at {:?} is not at b/2 from the rig centre",
                    rec.position
                )));
            }
        }
        Ok(rig)
    }

    /// Writes the file as pretty JSON (atomically).
    pub fn save(&self, path: &Path) -> Result<(), StereoError> {
        let err = |reason: String| StereoError::RigFile {
            path: path.to_path_buf(),
            reason,
        };
        let text = serde_json::to_string_pretty(self).map_err(|e| err(e.to_string()))?;
        streaks_image::write_bytes_atomically(path, text.as_bytes()).map_err(|e| err(e.to_string()))
    }

    /// Reads a file written by [`RigFile::save`] (lights are optional when written by hand).
    pub fn load(path: &Path) -> Result<Self, StereoError> {
        let err = |reason: String| StereoError::RigFile {
            path: path.to_path_buf(),
            reason,
        };
        let text = streaks_image::input::read_text(path, streaks_image::input::MAX_TEXT_BYTES)
            .map_err(|e| err(e.to_string()))?;
        let file: RigFile = serde_json::from_str(&text).map_err(|e| err(e.to_string()))?;
        file.rig().map_err(|e| err(e.to_string()))?;
        Ok(file)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn rig_json_round_trips() {
        let pose = Affine3A::from_rotation_translation(
            Quat::from_rotation_y(0.4) * Quat::from_rotation_x(-0.1),
            Vec3::new(2.0, 1.5, -3.0),
        );
        let rig = Rig::new(Intrinsics::from_yfov(640, 480, 0.7).unwrap(), 0.065, pose).unwrap();
        let road = rig.road_frame().unwrap();
        let lamp = Vec3::new(1.0, 5.0, -20.0);
        let lights = vec![
            LightRecord::Point {
                position: Placed::point(lamp, Some(&road)),
                intensity: [100.0, 90.0, 80.0],
                range: None,
            },
            LightRecord::Directional {
                direction: Placed::vector(-Vec3::Y, Some(&road)),
                irradiance: [0.1; 3],
            },
        ];
        let file = RigFile::new(&rig, lights);
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("rig.json");
        file.save(&p).unwrap();
        let back = RigFile::load(&p).unwrap();
        assert_eq!(back, file);
        let rig2 = back.rig().unwrap();
        assert_eq!(rig2.intrinsics(), rig.intrinsics());
        assert_eq!(rig2.baseline(), rig.baseline());
        assert!(rig2
            .world_from_rig()
            .abs_diff_eq(rig.world_from_rig(), 1e-6));
        // The road position of the lamp is the road frame's.
        let LightRecord::Point { position, .. } = &back.lights[0] else {
            panic!("not a point light")
        };
        let r = Vec3::from(position.road.unwrap());
        assert!((road.world_from_road_point(r) - lamp).length() < 1e-4);
        assert!((r.y - 5.0).abs() < 1e-5);
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.contains("\"kind\": \"point\"") && text.contains("\"handedness\": \"left\""));
    }

    #[test]
    fn inconsistent_files_are_errors() {
        let rig = Rig::new(
            Intrinsics::new(64, 48, 50.0).unwrap(),
            0.1,
            Affine3A::from_translation(Vec3::Y),
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("rig.json");
        let mut f = RigFile::new(&rig, vec![]);
        f.baseline = 0.0;
        std::fs::write(&p, serde_json::to_string(&f).unwrap()).unwrap();
        assert!(RigFile::load(&p)
            .unwrap_err()
            .to_string()
            .contains("baseline"));
        let mut f = RigFile::new(&rig, vec![]);
        f.right.position[0] += 0.5;
        std::fs::write(&p, serde_json::to_string(&f).unwrap()).unwrap();
        assert!(RigFile::load(&p).is_err());
        let mut f = RigFile::new(&rig, vec![]);
        f.intrinsics.principal_point = [10.0, 10.0];
        std::fs::write(&p, serde_json::to_string(&f).unwrap()).unwrap();
        assert!(RigFile::load(&p).is_err());
        std::fs::write(&p, "{").unwrap();
        assert!(RigFile::load(&p)
            .unwrap_err()
            .to_string()
            .contains("rig.json"));
        assert!(RigFile::load(&dir.path().join("none.json")).is_err());
    }
}
