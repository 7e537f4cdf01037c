//! The scene's environment light, from `scenes[i].extras.streaks.environment`:
//! `{"uri": "sky.exr", "strength": 1.0}` (an equirectangular linear-RGB OpenEXR map, named
//! relative to the scene's folder and read through the same checks as its images) or
//! `{"color": [r, g, b], "strength": 1.0}`; `strength` is optional (1). Other extras of the
//! scene are not ours and are ignored.

use super::Loader;
use crate::light::Environment;
use crate::scene::files::Uri;
use crate::scene::SceneError;
use glam::Vec3;
use serde::Deserialize;

/// `extras.streaks.environment` as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentExtras {
    /// The map's file, relative to the scene's folder.
    uri: Option<String>,
    /// A constant colour (linear RGB radiance before the strength).
    color: Option<[f32; 3]>,
    /// The factor on the map or the colour.
    strength: Option<f32>,
}

impl Loader<'_> {
    /// The environment `scene`'s extras give, if any.
    pub(super) fn environment(
        &self,
        scene: &gltf::Scene,
    ) -> Result<Option<Environment>, SceneError> {
        let element = format!("scene {}, extras.streaks.environment", scene.index());
        let bad = |reason: String| self.bad(&element, reason);
        let Some(raw) = scene.extras() else {
            return Ok(None);
        };
        let extras: serde_json::Value =
            serde_json::from_str(raw.get()).map_err(|e| bad(format!("extras: {e}")))?;
        let Some(value) = extras.pointer("/streaks/environment") else {
            return Ok(None);
        };
        let env: EnvironmentExtras =
            serde_json::from_value(value.clone()).map_err(|e| bad(e.to_string()))?;
        let strength = env.strength.unwrap_or(1.0);
        let made = match (env.uri, env.color) {
            (Some(uri), None) => {
                let path = match self.files.uri(&uri, &element)? {
                    Uri::File(path) => path,
                    Uri::Data(..) => {
                        return Err(bad(
                            "an environment map must be a file, not a data: URI".into()
                        ))
                    }
                };
                Environment::load_map(&path, strength)
            }
            (None, Some(c)) => Environment::constant(Vec3::from_array(c), strength),
            _ => {
                return Err(bad(
                    "give either \"uri\" (an equirectangular .exr) or \"color\" ([r, g, b])".into(),
                ))
            }
        };
        made.map(Some).map_err(|e| bad(error_chain(&e)))
    }
}

/// An error and its causes on one line.
fn error_chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{load_doc, load_err, test_doc_with_streaks_extra};
    use crate::light::Environment;
    use glam::Vec3;
    use serde_json::json;

    /// The test document with `environment` in its scene's extras, and its buffer.
    fn doc(environment: serde_json::Value) -> (serde_json::Value, Vec<u8>) {
        test_doc_with_streaks_extra("environment", environment)
    }

    #[test]
    fn a_colour_environment_is_read_with_its_strength() {
        let s = {
            let (d, bin) = doc(json!({"color": [0.1, 0.2, 0.3], "strength": 2.0}));
            load_doc(d, &bin)
        };
        assert_eq!(
            s.environment(),
            Some(&Environment::Constant {
                radiance: Vec3::new(0.2, 0.4, 0.6)
            })
        );
        // A lit scene: no warning about missing lights.
        assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    }

    #[test]
    fn a_map_next_to_the_scene_is_read() {
        let dir = tempfile::tempdir().unwrap();
        let img = streaks_image::RgbImage::from_fn(4, 3, |x, _| Vec3::splat(x as f32));
        streaks_image::exr::write_exr_rgb(&dir.path().join("sky.exr"), &img).unwrap();
        let (d, bin) = doc(json!({"uri": "sky.exr", "strength": 0.5}));
        let path = super::super::test_docs::write_embedded(dir.path(), d, &bin);
        let s = crate::scene::Scene::load(&path).unwrap();
        let map = s.environment().and_then(Environment::map).unwrap();
        assert_eq!(map.strength(), 0.5);
        assert_eq!(map.size(), (4, 3));
        assert!(map.path().ends_with("sky.exr"));
        // A PNG under that name is refused as not an EXR.
        std::fs::write(dir.path().join("sky.exr"), b"\x89PNG\r\n\x1a\n").unwrap();
        let err = crate::scene::Scene::load(&path).unwrap_err().to_string();
        assert!(
            err.contains("sky.exr") && err.contains("not an OpenEXR"),
            "{err}"
        );
    }

    #[test]
    fn bad_environments_are_errors_naming_the_element() {
        for (env, needle) in [
            (json!({"color": [1.0, -1.0, 0.0]}), "color"),
            (
                json!({"color": [1.0, 1.0, 1.0], "strength": -2.0}),
                "strength",
            ),
            (json!({"colour": [1.0, 1.0, 1.0]}), "colour"),
            (json!({}), "either"),
            (
                json!({"uri": "sky.exr", "color": [1.0, 1.0, 1.0]}),
                "either",
            ),
            (json!({"uri": "missing.exr"}), "missing.exr"),
            (json!({"uri": "../outside.exr"}), "outside"),
        ] {
            let (d, bin) = doc(env.clone());
            let err = load_err(d, &bin);
            assert!(
                err.contains("extras.streaks.environment") && err.contains(needle),
                "{env}: {err}"
            );
        }
    }
}
