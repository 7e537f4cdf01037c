//! The segmentation maps of a sample, in the Cityscapes label convention: the class table
//! (`dataset.json`'s `classes`), the instance numbering (`meta.json`'s `instances`) and the
//! files `semantic0.png`/`semantic1.png` and `instance0.png`/`instance1.png`.
//!
//! - `semanticN.png`: 8-bit greyscale, the label id of each pixel (Cityscapes'
//!   `*_labelIds.png`): the class of the pixel-centre ray's first hit, `sky` on a miss,
//!   `rain` where rain drops cover at least half of the pixel's samples
//!   (`streaks_stereo::render::RAIN_COVERAGE`).
//! - `instanceN.png`: 16-bit greyscale (Cityscapes' `*_instanceIds.png`): `labelId` for stuff
//!   and for things without an instance, `labelId * 1000 + k` for the pixels of an object
//!   (a node with `extras.streaks.instance` > 0), `k` its index among the sample's objects
//!   of that class (from 0, in the order of their instance ids). The label id is the first
//!   hit's class; under rain the instance map keeps the surface behind the drops (so there
//!   `instance / 1000` may differ from the semantic map's `rain`). `meta.json`'s `instances`
//!   maps each `(class, k)` to the scene's instance id (`extras.streaks.instance`); the
//!   parts of one object that are of another class (a car's lamps are `light_source`) are
//!   an instance of that class with the same id.
//!
//! The KITTI view's `semantic/` and `instance/` folders hold the same maps in KITTI's
//! semantic benchmark convention: the label ids unchanged, and the instance map as
//! `labelId * 256 + k` (uint16), where an instance index k above 255 is an error.

use crate::error::DatasetError;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The most objects of one class a sample's instance map can number: `k` must stay below
/// the 1000 that separates two classes' ids.
pub const MAX_INSTANCES_PER_CLASS: u32 = 1000;

/// The most objects of one class the KITTI view's instance map can number (`labelId * 256 +
/// k`).
pub const MAX_KITTI_INSTANCES_PER_CLASS: u32 = 256;

/// One class of `dataset.json`'s class table.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ClassRecord {
    /// The name (`extras.streaks.class`).
    pub name: String,
    /// The label id written in the maps.
    pub id: u8,
    /// The colour of colour-coded maps, sRGB.
    pub color: [u8; 3],
}

/// One object of a sample's instance map (`meta.json`'s `instances`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct InstanceRecord {
    /// The scene's instance id (`extras.streaks.instance`).
    pub id: u32,
    /// The class name.
    pub class: String,
    /// The index among the sample's objects of the class: the instance map holds
    /// `labelId * 1000 + k`.
    pub k: u32,
}

/// Checks a semantic map (`semantic0.png`): 8-bit, `size` pixels, every value a label id of
/// `classes`. Errors name the file.
pub fn check_semantic(
    path: &Path,
    size: (usize, usize),
    classes: &[ClassRecord],
) -> Result<(), DatasetError> {
    let img = open(path)?;
    if !matches!(img.color(), image::ColorType::L8) {
        return Err(invalid(path, "is not an 8-bit greyscale PNG".into()));
    }
    let img = img.into_luma8();
    check_dims(path, (img.width(), img.height()), size)?;
    match img
        .pixels()
        .find(|p| !classes.iter().any(|c| c.id == p.0[0]))
    {
        Some(p) => Err(invalid(
            path,
            format!("label id {} is not in dataset.json's classes", p.0[0]),
        )),
        None => Ok(()),
    }
}

/// Checks an instance map (`instance0.png`): 16-bit, `size` pixels, every value a label id
/// of `classes` or `labelId * 1000 + k` with `labelId` in `classes`. Errors name the file.
pub fn check_instance(
    path: &Path,
    size: (usize, usize),
    classes: &[ClassRecord],
) -> Result<(), DatasetError> {
    let img = open(path)?;
    if !matches!(img.color(), image::ColorType::L16) {
        return Err(invalid(path, "is not a 16-bit greyscale PNG".into()));
    }
    let img = img.into_luma16();
    check_dims(path, (img.width(), img.height()), size)?;
    let known = |v: u16| {
        let id = if u32::from(v) < MAX_INSTANCES_PER_CLASS {
            v
        } else {
            v / MAX_INSTANCES_PER_CLASS as u16
        };
        classes.iter().any(|c| u16::from(c.id) == id)
    };
    match img.pixels().find(|p| !known(p.0[0])) {
        Some(p) => Err(invalid(
            path,
            format!(
                "value {} is no label id of dataset.json's classes, nor one times 1000 plus k",
                p.0[0]
            ),
        )),
        None => Ok(()),
    }
}

fn open(path: &Path) -> Result<image::DynamicImage, DatasetError> {
    let bytes = std::fs::read(path).map_err(|e| DatasetError::io("read", path, e))?;
    image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .map_err(|e| invalid(path, format!("is not a PNG: {e}")))
}

fn check_dims(path: &Path, (w, h): (u32, u32), size: (usize, usize)) -> Result<(), DatasetError> {
    DatasetError::check_size(
        path,
        (w as usize, h as usize),
        size,
        "the dataset's images are",
    )
}

fn invalid(path: &Path, reason: String) -> DatasetError {
    DatasetError::Invalid {
        path: path.to_path_buf(),
        reason,
    }
}

#[cfg(feature = "render")]
pub use render::*;

#[cfg(feature = "render")]
mod render {
    use super::{ClassRecord, InstanceRecord, MAX_INSTANCES_PER_CLASS};
    use std::collections::BTreeMap;
    use streaks_render::class::Class;
    use streaks_render::scene::SceneObject;

    /// The class table of `dataset.json`: every class of the renderer ([`Class::ALL`]), in
    /// label-id order.
    pub fn class_table() -> Vec<ClassRecord> {
        Class::ALL
            .iter()
            .map(|c| ClassRecord {
                name: c.name().to_owned(),
                id: c.id(),
                color: c.color(),
            })
            .collect()
    }

    /// The numbering of a sample's objects in its instance maps: each labelled object with an
    /// instance id ([`SceneObject`] of a class, instance > 0) gets `k`, its index among the
    /// scene's objects of its class in the order of their instance ids. The numbering is the
    /// scene's, the same for both eyes.
    #[derive(Clone, Debug, PartialEq, Eq)]
    pub struct InstanceNumbering {
        /// `k` of each object slot of the scene's table (`None`: stuff or unlabelled).
        k: Vec<Option<u32>>,
        /// The records, by class id then `k`.
        records: Vec<InstanceRecord>,
    }

    impl InstanceNumbering {
        /// Numbers the objects of a scene's table `objects`
        /// ([`streaks_render::scene::Scene::objects`]). More than
        /// [`MAX_INSTANCES_PER_CLASS`] objects of one class is an error naming the class.
        pub fn new(objects: &[SceneObject]) -> Result<Self, String> {
            let mut by_class: BTreeMap<(u8, u32), Class> = BTreeMap::new();
            for o in objects {
                if let (Some(class), true) = (o.class, o.instance > 0) {
                    by_class.insert((class.id(), o.instance), class);
                }
            }
            let mut records = Vec::with_capacity(by_class.len());
            let mut ks: BTreeMap<(u8, u32), u32> = BTreeMap::new();
            let mut next: BTreeMap<u8, u32> = BTreeMap::new();
            for (&(id, instance), class) in &by_class {
                let k = next.entry(id).or_insert(0);
                if *k >= MAX_INSTANCES_PER_CLASS {
                    return Err(format!(
                        "the scene has more than {MAX_INSTANCES_PER_CLASS} objects of class \
                         {class}, more than an instance map numbers"
                    ));
                }
                ks.insert((id, instance), *k);
                records.push(InstanceRecord {
                    id: instance,
                    class: class.name().to_owned(),
                    k: *k,
                });
                *k += 1;
            }
            let k = objects
                .iter()
                .map(|o| o.class.and_then(|c| ks.get(&(c.id(), o.instance))).copied())
                .collect();
            Ok(Self { k, records })
        }

        /// `meta.json`'s `instances`.
        pub fn records(&self) -> &[InstanceRecord] {
            &self.records
        }

        /// The instance map (Cityscapes' `*_instanceIds.png` values, see the module
        /// documentation) of a render's `object` layer `slots`, with `per_class` as the
        /// multiplier of the label id (1000, or KITTI's 256). A slot outside the table is
        /// unlabelled.
        pub fn map(&self, objects: &[SceneObject], slots: &[u32], per_class: u32) -> Vec<u16> {
            slots
                .iter()
                .map(|&s| {
                    let object = objects
                        .get(s as usize)
                        .copied()
                        .unwrap_or(SceneObject::UNLABELLED);
                    let id = u32::from(object.label().id());
                    let k = self.k.get(s as usize).copied().flatten();
                    // Fits: label ids are below 65 and k below per_class.
                    k.map_or(id, |k| id * per_class + k) as u16
                })
                .collect()
        }

        /// The largest `k` of any object plus one (0 without objects).
        pub fn max_per_class(&self) -> u32 {
            self.records.iter().map(|r| r.k + 1).max().unwrap_or(0)
        }
    }
}

#[cfg(all(test, feature = "render"))]
mod tests {
    use super::*;
    use streaks_render::class::Class;
    use streaks_render::scene::SceneObject;

    fn obj(class: Option<Class>, instance: u32) -> SceneObject {
        SceneObject { class, instance }
    }

    /// Two cars and a car's lamp, a road, an unlabelled object with an instance and a car
    /// without one: Cityscapes' ids by hand.
    #[test]
    fn instance_ids_follow_cityscapes() {
        let mut objects = streaks_render::scene::base_table();
        objects.extend([
            obj(Some(Class::Car), 7),         // 2
            obj(Some(Class::Road), 0),        // 3
            obj(Some(Class::Car), 3),         // 4
            obj(Some(Class::LightSource), 3), // 5
            obj(None, 9),                     // 6
            obj(Some(Class::Car), 0),         // 7
        ]);
        let n = InstanceNumbering::new(&objects).unwrap();
        let slots = [0, 1, 2, 3, 4, 5, 6, 7, 99];
        // Car (26): instance 3 is k 0, instance 7 is k 1 (by instance id); the lamp (35)
        // of car 3 is k 0 of its class.
        assert_eq!(
            n.map(&objects, &slots, 1000),
            [23, 0, 26_001, 7, 26_000, 35_000, 0, 26, 0]
        );
        assert_eq!(
            n.map(&objects, &slots, 256),
            [23, 0, 26 * 256 + 1, 7, 26 * 256, 35 * 256, 0, 26, 0]
        );
        let rec = |id, class: &str, k| InstanceRecord {
            id,
            class: class.into(),
            k,
        };
        assert_eq!(
            n.records(),
            [
                rec(3, "car", 0),
                rec(7, "car", 1),
                rec(3, "light_source", 0)
            ]
        );
        assert_eq!(n.max_per_class(), 2);
    }

    #[test]
    fn more_instances_than_a_class_can_number_is_an_error() {
        let mut objects = streaks_render::scene::base_table();
        objects.extend((1..=1001).map(|i| obj(Some(Class::Person), i)));
        let err = InstanceNumbering::new(&objects).unwrap_err();
        assert!(err.contains("1000") && err.contains("person"), "{err}");
    }

    #[test]
    fn maps_are_checked_against_the_class_table() {
        let dir = tempfile::tempdir().unwrap();
        let classes = class_table();
        let sem = dir.path().join("semantic0.png");
        let ok = image::GrayImage::from_raw(2, 1, vec![7, 26]).unwrap();
        save(&sem, &ok);
        check_semantic(&sem, (2, 1), &classes).unwrap();
        let err = check_semantic(&sem, (3, 1), &classes).unwrap_err();
        assert!(err.to_string().contains("semantic0.png"), "{err}");
        let bad = image::GrayImage::from_raw(2, 1, vec![7, 99]).unwrap();
        save(&sem, &bad);
        let err = check_semantic(&sem, (2, 1), &classes).unwrap_err();
        assert!(err.to_string().contains("label id 99"), "{err}");
        let inst = dir.path().join("instance0.png");
        let ok =
            image::ImageBuffer::<image::Luma<u16>, _>::from_raw(3, 1, vec![7, 26_001, 23]).unwrap();
        save(&inst, &ok);
        check_instance(&inst, (3, 1), &classes).unwrap();
        // An 8-bit map is not an instance map, and 99_000 / 1000 is no label id.
        let err = check_instance(&sem, (2, 1), &classes).unwrap_err();
        assert!(err.to_string().contains("16-bit"), "{err}");
        let bad = image::ImageBuffer::<image::Luma<u16>, _>::from_raw(1, 1, vec![60_000]).unwrap();
        save(&inst, &bad);
        let err = check_instance(&inst, (1, 1), &classes).unwrap_err();
        assert!(err.to_string().contains("value 60000"), "{err}");
    }

    fn save<P: image::PixelWithColorType, C: std::ops::Deref<Target = [P::Subpixel]>>(
        path: &Path,
        img: &image::ImageBuffer<P, C>,
    ) where
        [P::Subpixel]: image::EncodableLayout,
    {
        streaks_image::png::write_png_buffer(path, img).unwrap();
    }
}
