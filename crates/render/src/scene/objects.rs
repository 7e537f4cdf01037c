//! What each triangle is part of, for the segmentation ground truth: the scene's table of
//! objects ([`SceneObject`]: a semantic class and an instance id, from the glTF nodes'
//! `extras.streaks.class` and `extras.streaks.instance`, see [`crate::class`]) and the slot of
//! that table every triangle ([`super::TriangleMesh::triangle_objects`]) and every instance
//! ([`super::Instance::object`]) points to.
//!
//! The table has one slot per distinct (class, instance), so a scene stores one `u32` per
//! triangle and nothing per ray. Its first two slots are always the same: [`SKY_OBJECT`], what
//! a camera ray that hits nothing sees (the integrator's `object` layer on a miss), and
//! [`UNLABELLED_OBJECT`], the triangles nothing labels (every triangle of an OBJ scene).

use crate::class::Class;
use std::collections::HashMap;

/// What a triangle is part of: its semantic class (`None`: unlabelled) and the object it
/// belongs to (`extras.streaks.instance`; 0 for none, as for stuff such as the road).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SceneObject {
    /// The semantic class; `None` where no node says (or names an unknown class).
    pub class: Option<Class>,
    /// The instance id shared by the nodes of one object (a car's body, wheels and lamps);
    /// 0 for none.
    pub instance: u32,
}

impl SceneObject {
    /// The sky: what a camera ray that hits nothing sees.
    pub const SKY: SceneObject = SceneObject {
        class: Some(Class::Sky),
        instance: 0,
    };

    /// A triangle that no node labels.
    pub const UNLABELLED: SceneObject = SceneObject {
        class: None,
        instance: 0,
    };

    /// The class written in a semantic map: [`Class::Unlabeled`] for an unlabelled object.
    pub fn label(self) -> Class {
        self.class.unwrap_or(Class::Unlabeled)
    }
}

/// The slot of [`SceneObject::SKY`] in every scene's table (the `object` layer on a miss).
pub const SKY_OBJECT: u32 = 0;

/// The slot of [`SceneObject::UNLABELLED`] in every scene's table (the slot of a triangle
/// nothing labels).
pub const UNLABELLED_OBJECT: u32 = 1;

/// The table every scene starts from: the sky and the unlabelled object, at [`SKY_OBJECT`]
/// and [`UNLABELLED_OBJECT`].
pub fn base_table() -> Vec<SceneObject> {
    vec![SceneObject::SKY, SceneObject::UNLABELLED]
}

/// A table under construction that gives each distinct object one slot, in the order first
/// met (so the same file gives the same table), starting from [`base_table`].
#[derive(Clone, Debug)]
pub struct ObjectTable {
    objects: Vec<SceneObject>,
    slots: HashMap<SceneObject, u32>,
}

impl Default for ObjectTable {
    fn default() -> Self {
        let objects = base_table();
        let slots = objects
            .iter()
            .enumerate()
            .map(|(i, &o)| (o, i as u32))
            .collect();
        Self { objects, slots }
    }
}

impl ObjectTable {
    /// The slot of `object`, added if it is new.
    pub fn slot(&mut self, object: SceneObject) -> u32 {
        let next = self.objects.len() as u32;
        let slot = *self.slots.entry(object).or_insert(next);
        if slot == next {
            self.objects.push(object);
        }
        slot
    }

    /// The table: the objects by slot.
    pub fn into_objects(self) -> Vec<SceneObject> {
        self.objects
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_slot_per_distinct_object_after_the_sky_and_the_unlabelled() {
        let mut t = ObjectTable::default();
        let car3 = SceneObject {
            class: Some(Class::Car),
            instance: 3,
        };
        let lamp3 = SceneObject {
            class: Some(Class::LightSource),
            instance: 3,
        };
        assert_eq!(t.slot(car3), 2);
        assert_eq!(t.slot(lamp3), 3);
        assert_eq!(t.slot(car3), 2);
        assert_eq!(t.slot(SceneObject::UNLABELLED), UNLABELLED_OBJECT);
        assert_eq!(t.slot(SceneObject::SKY), SKY_OBJECT);
        assert_eq!(
            t.into_objects(),
            [SceneObject::SKY, SceneObject::UNLABELLED, car3, lamp3]
        );
        assert_eq!(SceneObject::UNLABELLED.label(), Class::Unlabeled);
        assert_eq!(car3.label(), Class::Car);
    }
}
