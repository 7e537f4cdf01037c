//! Semantic classes: what a scene's object is, for the segmentation ground truth.
//!
//! A glTF node says what it is with `extras.streaks.class` (a name of [`Class::ALL`], for
//! example `"car"`) and which object it is part of with `extras.streaks.instance` (an integer
//! shared by the nodes of one object: a car's body, wheels, glass and lamps). Children inherit
//! both from their parent unless they set their own. A node with neither is unlabelled.
//!
//! The label ids follow the Cityscapes convention (`labelId` of Cordts et al. 2016, the
//! `cityscapesScripts` `labels.py` table) where Cityscapes has the class, so that tools
//! written for Cityscapes read the maps; the classes that matter at night in the rain and
//! that Cityscapes lacks (lane markings, light sources, rain, street furniture) take ids from
//! 34 up. The colours are Cityscapes' where it has the class.

/// A semantic class of the scene contract.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Class {
    /// Nothing known (no label, or the sky where a scene has none).
    Unlabeled,
    /// The carriageway (asphalt, cobbles, standing water on it).
    Road,
    /// Pavements and kerbs.
    Sidewalk,
    /// Tram or rail tracks.
    RailTrack,
    /// Buildings, shop fronts and their windows.
    Building,
    /// Free-standing walls.
    Wall,
    /// Fences and railings.
    Fence,
    /// Lamp posts, telephone poles, sign posts, bollards.
    Pole,
    /// Traffic-light heads.
    TrafficLight,
    /// Sign plates.
    TrafficSign,
    /// Trees, hedges.
    Vegetation,
    /// Grass and soil verges.
    Terrain,
    /// The sky (what a camera ray that hits nothing sees).
    Sky,
    /// People.
    Person,
    /// Cars (saloons, hatchbacks, estates, SUVs).
    Car,
    /// Vans and lorries.
    Truck,
    /// Buses.
    Bus,
    /// Trams and trains.
    Train,
    /// Painted lane markings, crosswalks and road arrows.
    Marking,
    /// Light-emitting parts: lamp lenses, headlights, tail lights, lit signs.
    LightSource,
    /// Rain drops covering the pixel.
    Rain,
    /// Bus stops, benches, bins and other street furniture.
    StreetFurniture,
}

impl Class {
    /// Every class, in label-id order.
    pub const ALL: [Class; 22] = [
        Class::Unlabeled,
        Class::Road,
        Class::Sidewalk,
        Class::RailTrack,
        Class::Building,
        Class::Wall,
        Class::Fence,
        Class::Pole,
        Class::TrafficLight,
        Class::TrafficSign,
        Class::Vegetation,
        Class::Terrain,
        Class::Sky,
        Class::Person,
        Class::Car,
        Class::Truck,
        Class::Bus,
        Class::Train,
        Class::Marking,
        Class::LightSource,
        Class::Rain,
        Class::StreetFurniture,
    ];

    /// The name used in `extras.streaks.class` and in the dataset's class table.
    pub fn name(self) -> &'static str {
        match self {
            Class::Unlabeled => "unlabeled",
            Class::Road => "road",
            Class::Sidewalk => "sidewalk",
            Class::RailTrack => "rail_track",
            Class::Building => "building",
            Class::Wall => "wall",
            Class::Fence => "fence",
            Class::Pole => "pole",
            Class::TrafficLight => "traffic_light",
            Class::TrafficSign => "traffic_sign",
            Class::Vegetation => "vegetation",
            Class::Terrain => "terrain",
            Class::Sky => "sky",
            Class::Person => "person",
            Class::Car => "car",
            Class::Truck => "truck",
            Class::Bus => "bus",
            Class::Train => "train",
            Class::Marking => "marking",
            Class::LightSource => "light_source",
            Class::Rain => "rain",
            Class::StreetFurniture => "street_furniture",
        }
    }

    /// The label id written in the semantic maps (Cityscapes' `labelId` where it has the
    /// class, 34 and up otherwise).
    pub fn id(self) -> u8 {
        match self {
            Class::Unlabeled => 0,
            Class::Road => 7,
            Class::Sidewalk => 8,
            Class::RailTrack => 10,
            Class::Building => 11,
            Class::Wall => 12,
            Class::Fence => 13,
            Class::Pole => 17,
            Class::TrafficLight => 19,
            Class::TrafficSign => 20,
            Class::Vegetation => 21,
            Class::Terrain => 22,
            Class::Sky => 23,
            Class::Person => 24,
            Class::Car => 26,
            Class::Truck => 27,
            Class::Bus => 28,
            Class::Train => 31,
            Class::Marking => 34,
            Class::LightSource => 35,
            Class::Rain => 36,
            Class::StreetFurniture => 37,
        }
    }

    /// The colour of the class in colour-coded maps (sRGB), Cityscapes' where it has one.
    pub fn color(self) -> [u8; 3] {
        match self {
            Class::Unlabeled => [0, 0, 0],
            Class::Road => [128, 64, 128],
            Class::Sidewalk => [244, 35, 232],
            Class::RailTrack => [230, 150, 140],
            Class::Building => [70, 70, 70],
            Class::Wall => [102, 102, 156],
            Class::Fence => [190, 153, 153],
            Class::Pole => [153, 153, 153],
            Class::TrafficLight => [250, 170, 30],
            Class::TrafficSign => [220, 220, 0],
            Class::Vegetation => [107, 142, 35],
            Class::Terrain => [152, 251, 152],
            Class::Sky => [70, 130, 180],
            Class::Person => [220, 20, 60],
            Class::Car => [0, 0, 142],
            Class::Truck => [0, 0, 70],
            Class::Bus => [0, 60, 100],
            Class::Train => [0, 80, 100],
            Class::Marking => [255, 255, 255],
            Class::LightSource => [255, 240, 150],
            Class::Rain => [120, 200, 255],
            Class::StreetFurniture => [180, 120, 60],
        }
    }

    /// The class of a name (as [`Class::name`] gives it); `None` for an unknown name.
    pub fn from_name(name: &str) -> Option<Class> {
        Class::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The class of a label id; `None` for an id no class has.
    pub fn from_id(id: u8) -> Option<Class> {
        Class::ALL.into_iter().find(|c| c.id() == id)
    }
}

impl std::fmt::Display for Class {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_ids_are_unique_and_round_trip() {
        for (i, a) in Class::ALL.iter().enumerate() {
            assert_eq!(Class::from_name(a.name()), Some(*a));
            assert_eq!(Class::from_id(a.id()), Some(*a));
            for b in &Class::ALL[i + 1..] {
                assert_ne!(a.name(), b.name());
                assert!(a.id() < b.id(), "ids in ALL order: {a} {b}");
            }
        }
        assert_eq!(Class::from_name("lamp"), None);
    }

    #[test]
    fn cityscapes_ids_where_cityscapes_has_the_class() {
        // cityscapesScripts labels.py: road 7, sidewalk 8, building 11, pole 17, sky 23, car 26.
        assert_eq!(Class::Road.id(), 7);
        assert_eq!(Class::Sidewalk.id(), 8);
        assert_eq!(Class::Building.id(), 11);
        assert_eq!(Class::Pole.id(), 17);
        assert_eq!(Class::Sky.id(), 23);
        assert_eq!(Class::Car.id(), 26);
        assert_eq!(Class::Road.color(), [128, 64, 128]);
    }
}
