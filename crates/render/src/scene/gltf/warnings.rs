//! The glTF loader's warnings, gathered by feature: each thing the renderer skips or renders
//! differently is named once per file, with what is rendered instead and how many elements
//! use it (`KHR_materials_anisotropy on 49 materials: rendered as an isotropic surface
//! (material "a" (0); material "b" (1); material "c" (2) and 46 more)`), not once per element.

use std::path::Path;

/// How many of a feature's elements a warning names before it says how many more there are.
const NAMED: usize = 3;

/// One feature the file uses that the renderer does not honour as written.
#[derive(Debug)]
struct Feature {
    /// What is not honoured (`KHR_materials_anisotropy`, `occlusionTexture`, ...).
    what: String,
    /// How the elements that use it are rendered instead.
    without: String,
    /// The elements that use it, in the order met: their kind (singular: `material`) and
    /// their label for messages.
    elements: Vec<(&'static str, String)>,
}

/// The warnings of one file: features in the order first met, each with the elements that
/// use it, and plain notes that concern the file as a whole.
#[derive(Debug, Default)]
pub(super) struct Warnings {
    features: Vec<Feature>,
    notes: Vec<String>,
}

/// The plural of an element kind (`material` -> `materials`, `mesh` -> `meshes`).
fn plural(kind: &str) -> String {
    if kind.ends_with("sh") {
        format!("{kind}es")
    } else {
        format!("{kind}s")
    }
}

impl Warnings {
    /// Records that `element`, of kind `kind` (singular: `material`, `primitive`, `node`),
    /// uses `what`, which is rendered `without` (`rendered as an isotropic surface`). The
    /// same (`what`, `without`) from several elements makes one warning; an element named
    /// twice for it counts once.
    pub(super) fn add(&mut self, what: &str, kind: &'static str, element: &str, without: &str) {
        let index = match self
            .features
            .iter()
            .position(|f| f.what == what && f.without == without)
        {
            Some(i) => i,
            None => {
                self.features.push(Feature {
                    what: what.to_owned(),
                    without: without.to_owned(),
                    elements: Vec::new(),
                });
                self.features.len() - 1
            }
        };
        let elements = &mut self.features[index].elements;
        if !elements.iter().any(|(k, e)| *k == kind && e == element) {
            elements.push((kind, element.to_owned()));
        }
    }

    /// Records a warning about the file as a whole (no elements to count); an identical note
    /// is kept once.
    pub(super) fn note(&mut self, message: String) {
        if !self.notes.contains(&message) {
            self.notes.push(message);
        }
    }

    /// Whether a warning about `what` has been recorded.
    #[cfg(test)]
    pub(super) fn has(&self, what: &str) -> bool {
        self.features.iter().any(|f| f.what == what)
    }

    /// The warnings as lines for the user, each prefixed with the file's path: the notes,
    /// then one line per feature.
    pub(super) fn lines(&self, path: &Path) -> Vec<String> {
        let path = path.display();
        let mut lines: Vec<String> = self.notes.iter().map(|n| format!("{path}: {n}")).collect();
        for f in &self.features {
            // "49 materials" or "2 materials and 1 texture", kinds in the order first met.
            let mut kinds: Vec<(&str, usize)> = Vec::new();
            for (kind, _) in &f.elements {
                match kinds.iter_mut().find(|(k, _)| k == kind) {
                    Some((_, n)) => *n += 1,
                    None => kinds.push((kind, 1)),
                }
            }
            let counts: Vec<String> = kinds
                .iter()
                .map(|&(kind, n)| match n {
                    1 => format!("1 {kind}"),
                    n => format!("{n} {}", plural(kind)),
                })
                .collect();
            // Labels may hold commas ("mesh 0, primitive 1"): they are separated by semicolons.
            let named: Vec<&str> = f
                .elements
                .iter()
                .take(NAMED)
                .map(|(_, e)| e.as_str())
                .collect();
            let more = match f.elements.len().saturating_sub(NAMED) {
                0 => String::new(),
                n => format!(" and {n} more"),
            };
            lines.push(format!(
                "{path}: {} on {}: {} ({}{more})",
                f.what,
                counts.join(" and "),
                f.without,
                named.join("; ")
            ));
        }
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_per_feature_with_counts_and_the_first_elements() {
        let mut w = Warnings::default();
        for i in 0..49 {
            let label = format!("material {i}");
            let without = "rendered as an isotropic surface";
            w.add("KHR_materials_anisotropy", "material", &label, without);
            // The same element twice counts once.
            w.add("KHR_materials_anisotropy", "material", &label, without);
        }
        w.add("KHR_x", "material", "material 0", "ignored");
        w.add("KHR_x", "texture", "texture 2", "ignored");
        w.add("Points mode", "primitive", "mesh 0, primitive 1", "skipped");
        w.note("the file has no scene".into());
        w.note("the file has no scene".into());
        let lines = w.lines(Path::new("a.gltf"));
        assert_eq!(
            lines,
            [
                "a.gltf: the file has no scene",
                "a.gltf: KHR_materials_anisotropy on 49 materials: rendered as an isotropic \
                 surface (material 0; material 1; material 2 and 46 more)",
                "a.gltf: KHR_x on 1 material and 1 texture: ignored (material 0; texture 2)",
                "a.gltf: Points mode on 1 primitive: skipped (mesh 0, primitive 1)",
            ]
        );
        assert!(w.has("KHR_x") && !w.has("KHR_y"));
        assert_eq!(plural("mesh"), "meshes");
    }
}
