//! The nodes' semantic tags, `extras.streaks.class` (a name of [`Class::ALL`]) and
//! `extras.streaks.instance` (a u32), for the segmentation layers ([`crate::scene::objects`]).
//!
//! Each key is inherited from the parent unless the node sets it, so a car's parent node may
//! carry its instance and class for all its parts, and a lamp lens below it set its own
//! class (`light_source`) and keep the car's instance. An unknown class name is a warning
//! naming the node, which then counts as unlabelled (and so do its children that set no class
//! of their own); a key of the wrong type is an error naming the node and the key. Other
//! extras of a node are not ours and are ignored.

use super::{node_label, Loader};
use crate::class::Class;
use crate::scene::{SceneError, SceneObject};

/// What a node's walk passes to its children: the tag in force.
pub(super) type NodeTag = SceneObject;

impl Loader<'_> {
    /// The tag of `node` below a parent whose tag is `parent`: each key of the node's
    /// `extras.streaks` replaces the parent's.
    pub(super) fn node_tag(
        &mut self,
        node: &gltf::Node,
        parent: NodeTag,
    ) -> Result<NodeTag, SceneError> {
        let Some(raw) = node.extras() else {
            return Ok(parent);
        };
        let label = node_label(node);
        let extras: serde_json::Value = serde_json::from_str(raw.get())
            .map_err(|e| self.bad(&label, format!("extras: {e}")))?;
        let Some(streaks) = extras.get("streaks") else {
            return Ok(parent);
        };
        let Some(streaks) = streaks.as_object() else {
            return Err(self.bad(&label, "extras.streaks is not an object"));
        };
        let mut tag = parent;
        if let Some(class) = streaks.get("class") {
            let Some(name) = class.as_str() else {
                return Err(self.bad(
                    &label,
                    format!("extras.streaks.class is not a string: {class}"),
                ));
            };
            tag.class = Class::from_name(name);
            if tag.class.is_none() {
                let what = format!("extras.streaks.class {name:?} (not a known class)");
                self.warn(&what, "node", &label, "the node is unlabelled");
            }
        }
        if let Some(instance) = streaks.get("instance") {
            tag.instance = instance
                .as_u64()
                .and_then(|i| u32::try_from(i).ok())
                .ok_or_else(|| {
                    self.bad(
                        &label,
                        format!(
                            "extras.streaks.instance is not an integer in [0, 2^32 - 1]: \
                             {instance}"
                        ),
                    )
                })?;
        }
        Ok(tag)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{
        assert_same_hits, box_placements, error, load_doc, placed_boxes, test_doc,
    };
    use crate::class::Class;
    use crate::geometry::Ray;
    use crate::scene::{Scene, SceneObject, SKY_OBJECT, UNLABELLED_OBJECT};
    use glam::Vec3;
    use serde_json::json;

    fn object(class: Class, instance: u32) -> SceneObject {
        SceneObject {
            class: Some(class),
            instance,
        }
    }

    /// The object of the first hit of the ray from `origin` along `dir`.
    fn hit_object(scene: &Scene, origin: Vec3, dir: Vec3) -> SceneObject {
        let hit = scene.intersect(&Ray::new(origin, dir)).expect("a hit");
        scene.objects[hit.object as usize]
    }

    /// The quad of the test document is node "child" below node "parent" (at x in [20, 22],
    /// y = 1, z in [0, 2]); the emissive triangle is node "lamp" (z = -3, x, y in [0, 1]).
    const QUAD: (Vec3, Vec3) = (Vec3::new(21.0, 5.0, 1.0), Vec3::NEG_Y);
    const LAMP: (Vec3, Vec3) = (Vec3::new(0.2, 0.2, 5.0), Vec3::NEG_Z);

    #[test]
    fn a_child_inherits_each_key_it_does_not_set() {
        let (mut doc, bin) = test_doc();
        doc["nodes"][0]["extras"] = json!({"streaks": {"class": "car", "instance": 3}});
        doc["nodes"][1]["extras"] = json!({"streaks": {"class": "light_source"}, "other": 1});
        let scene = load_doc(doc, &bin);
        assert_eq!(
            hit_object(&scene, QUAD.0, QUAD.1),
            object(Class::LightSource, 3)
        );
        assert_eq!(hit_object(&scene, LAMP.0, LAMP.1), SceneObject::UNLABELLED);
        // The parent's own tag has a slot though it has no mesh; the table is deduplicated.
        assert_eq!(
            scene.objects,
            [
                SceneObject::SKY,
                SceneObject::UNLABELLED,
                object(Class::Car, 3),
                object(Class::LightSource, 3)
            ]
        );
        assert_eq!(scene.mesh.triangle_objects, [3, 3, UNLABELLED_OBJECT]);
        // Only the instance on the child: the parent's class stays.
        let (mut doc, bin) = test_doc();
        doc["nodes"][0]["extras"] = json!({"streaks": {"class": "car", "instance": 3}});
        doc["nodes"][1]["extras"] = json!({"streaks": {"instance": 4}});
        let scene = load_doc(doc, &bin);
        assert_eq!(hit_object(&scene, QUAD.0, QUAD.1), object(Class::Car, 4));
        // An untagged scene is all unlabelled.
        let (doc, bin) = test_doc();
        let scene = load_doc(doc, &bin);
        assert_eq!(scene.objects, crate::scene::base_table());
        assert!(scene
            .mesh
            .triangle_objects
            .iter()
            .all(|&o| o == UNLABELLED_OBJECT));
        assert_ne!(SKY_OBJECT, UNLABELLED_OBJECT);
    }

    #[test]
    fn an_unknown_class_warns_naming_the_node_and_is_unlabelled() {
        let (mut doc, bin) = test_doc();
        doc["nodes"][0]["extras"] = json!({"streaks": {"class": "car", "instance": 3}});
        doc["nodes"][1]["extras"] = json!({"streaks": {"class": "spaceship"}});
        let scene = load_doc(doc, &bin);
        let got = hit_object(&scene, QUAD.0, QUAD.1);
        assert_eq!(
            got,
            SceneObject {
                class: None,
                instance: 3
            }
        );
        assert_eq!(got.label(), Class::Unlabeled);
        let warning = scene
            .warnings
            .iter()
            .find(|w| w.contains("spaceship"))
            .expect("a warning");
        assert!(
            warning.contains("node \"child\" (1)") && warning.contains("unlabelled"),
            "{warning}"
        );
    }

    #[test]
    fn tags_of_the_wrong_type_are_errors_naming_node_and_key() {
        for (streaks, key) in [
            (json!({"class": 5}), "extras.streaks.class"),
            (json!({"instance": -1}), "extras.streaks.instance"),
            (json!({"instance": "3"}), "extras.streaks.instance"),
            (
                json!({"instance": 5_000_000_000u64}),
                "extras.streaks.instance",
            ),
            (json!({"instance": 2.5}), "extras.streaks.instance"),
            (json!([1]), "extras.streaks"),
        ] {
            let (mut doc, bin) = test_doc();
            doc["nodes"][0]["extras"] = json!({ "streaks": streaks });
            let err = error(doc, &bin);
            assert!(
                err.contains("node \"parent\" (0)") && err.contains(key),
                "{streaks}: {err}"
            );
        }
    }

    /// Instanced and flattened placements of one mesh tagged per node (two cars of one
    /// class, a child with its own class) give every ray the same object, and an instance
    /// carries its node's slot.
    #[test]
    fn instances_carry_their_nodes_objects() {
        let mut placements = box_placements();
        for (i, p) in placements.iter_mut().enumerate() {
            p["extras"] = match i {
                0 => json!({"streaks": {"class": "bus"}}),
                1 => json!({"streaks": {"instance": 7}}),
                _ => json!({"streaks": {"class": "car", "instance": i}}),
            };
        }
        let tag_parent = |doc: &mut serde_json::Value| {
            doc["nodes"][0]["extras"] = json!({"streaks": {"class": "car", "instance": 1}});
        };
        let (mut doc, bin) = placed_boxes(&placements, true);
        tag_parent(&mut doc);
        let instanced = load_doc(doc, &bin);
        let (mut doc, bin) = placed_boxes(&placements, false);
        tag_parent(&mut doc);
        let flat = load_doc(doc, &bin);
        let want = |i: usize| match i {
            0 => object(Class::Bus, 1),
            1 => object(Class::Car, 7),
            _ => object(Class::Car, i as u32),
        };
        let placed: Vec<SceneObject> = instanced
            .instances
            .instances
            .iter()
            .map(|inst| instanced.objects[inst.object as usize])
            .collect();
        assert_eq!(placed, (0..placements.len()).map(want).collect::<Vec<_>>());
        for (i, tris) in flat.mesh.triangle_objects.chunks(14).enumerate() {
            assert!(tris.iter().all(|&o| flat.objects[o as usize] == want(i)));
        }
        assert!(assert_same_hits(&instanced, &flat, 3000) > 500);
    }
}
