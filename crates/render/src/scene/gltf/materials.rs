//! Materials: glTF metallic-roughness with KHR_materials_specular, _ior, _sheen,
//! _iridescence, _clearcoat, _transmission and _volume, the paper's models and the road flag from `extras.streaks`, and
//! the glTF default material.

use super::textures::{JsonTextureInfo, UvTransform};
use super::Loader;
use crate::material::{
    Alpha, AlphaMode, GltfPbrParams, Material, PaperModel, Reflectance, Retro, Volume, Wetness,
};
use crate::normal_map::NormalMap;
use crate::scene::{validate, SceneError};
use crate::texture::{ColorSpace, TextureRef};
use glam::{Vec3, Vec4};
use serde::de::DeserializeOwned;
use serde::Deserialize;

/// `extras.streaks` of a material (see the `scene` module documentation).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct StreaksExtras {
    /// The paper model; absent, the material is glTF metallic-roughness and `extras.streaks`
    /// may only carry `road`.
    #[serde(default)]
    bsdf: Option<StreaksBsdf>,
    /// Marks the road surface (datasets mask the pixels whose first hit has such a
    /// material); no effect on shading.
    #[serde(default)]
    road: bool,
    #[serde(default)]
    kd: Option<[f32; 3]>,
    #[serde(default)]
    ks: Option<[f32; 3]>,
    #[serde(default)]
    alpha: Option<f32>,
    #[serde(default)]
    shininess: Option<f32>,
    #[serde(default)]
    alpha_dry: Option<f32>,
    #[serde(default)]
    ks_dry: Option<[f32; 3]>,
    /// Glass beads' retroreflectance (ggx only; see [`crate::bsdf::Retroreflective`]).
    #[serde(default)]
    kr: Option<[f32; 3]>,
    /// The beads' retroreflective cone's width, radians (default
    /// [`crate::bsdf::BEAD_CONE_WIDTH`]).
    #[serde(default)]
    retro_width: Option<f32>,
}

#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum StreaksBsdf {
    Ggx,
    Ward,
    BlinnPhong,
}

/// A material's KHR_materials_specular and KHR_materials_ior parameters.
pub(super) struct Specular {
    factor: f32,
    texture: Option<TextureRef>,
    color: Vec3,
    color_texture: Option<TextureRef>,
    ior: f32,
}

/// A material's KHR_materials_clearcoat object, as the JSON has it, and its decoded textures.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Clearcoat {
    #[serde(default)]
    clearcoat_factor: f32,
    clearcoat_texture: Option<JsonTextureInfo>,
    #[serde(default)]
    clearcoat_roughness_factor: f32,
    clearcoat_roughness_texture: Option<JsonTextureInfo>,
    clearcoat_normal_texture: Option<JsonNormalTextureInfo>,
    #[serde(skip)]
    texture: Option<TextureRef>,
    #[serde(skip)]
    roughness_texture: Option<TextureRef>,
    #[serde(skip)]
    normal_map: Option<NormalMap>,
}

/// A normalTextureInfo read from the JSON (KHR_materials_clearcoat's clearcoatNormalTexture):
/// a textureInfo with a `scale`.
#[derive(Clone, Copy, Debug, Deserialize)]
pub(super) struct JsonNormalTextureInfo {
    #[serde(flatten)]
    info: JsonTextureInfo,
    #[serde(default = "one")]
    scale: f32,
}

/// normalTextureInfo's default scale.
fn one() -> f32 {
    1.0
}

/// A material's KHR_materials_sheen object, as the JSON has it, and its decoded textures.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Sheen {
    #[serde(default)]
    sheen_color_factor: [f32; 3],
    sheen_color_texture: Option<JsonTextureInfo>,
    #[serde(default)]
    sheen_roughness_factor: f32,
    sheen_roughness_texture: Option<JsonTextureInfo>,
    #[serde(skip)]
    color_texture: Option<TextureRef>,
    #[serde(skip)]
    roughness_texture: Option<TextureRef>,
}

/// A material's KHR_materials_iridescence object, as the JSON has it, and its decoded
/// textures.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Iridescence {
    #[serde(default)]
    iridescence_factor: f32,
    iridescence_texture: Option<JsonTextureInfo>,
    #[serde(default = "film_ior")]
    iridescence_ior: f32,
    #[serde(default = "film_min")]
    iridescence_thickness_minimum: f32,
    #[serde(default = "film_max")]
    iridescence_thickness_maximum: f32,
    iridescence_thickness_texture: Option<JsonTextureInfo>,
    #[serde(skip)]
    texture: Option<TextureRef>,
    #[serde(skip)]
    thickness_texture: Option<TextureRef>,
}

/// KHR_materials_iridescence's defaults: the film's index, its thickness range in nm.
fn film_ior() -> f32 {
    1.3
}
fn film_min() -> f32 {
    100.0
}
fn film_max() -> f32 {
    400.0
}

impl Default for Iridescence {
    fn default() -> Self {
        Iridescence {
            iridescence_factor: 0.0,
            iridescence_texture: None,
            iridescence_ior: film_ior(),
            iridescence_thickness_minimum: film_min(),
            iridescence_thickness_maximum: film_max(),
            iridescence_thickness_texture: None,
            texture: None,
            thickness_texture: None,
        }
    }
}

/// A material's KHR_materials_transmission object, as the JSON has it, and its decoded texture.
#[derive(Debug, Default, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct Transmission {
    #[serde(default)]
    transmission_factor: f32,
    transmission_texture: Option<JsonTextureInfo>,
    #[serde(skip)]
    texture: Option<TextureRef>,
}

/// A material's KHR_materials_volume object, as the JSON has it.
#[derive(Debug, Deserialize)]
#[serde(rename_all = "camelCase")]
pub(super) struct JsonVolume {
    #[serde(default)]
    thickness_factor: f32,
    thickness_texture: Option<JsonTextureInfo>,
    #[serde(default = "infinite")]
    attenuation_distance: f32,
    #[serde(default = "white")]
    attenuation_color: [f32; 3],
}

/// KHR_materials_volume's default attenuationDistance: no attenuation.
pub(super) fn infinite() -> f32 {
    f32::INFINITY
}

/// KHR_materials_volume's default attenuationColor.
pub(super) fn white() -> [f32; 3] {
    [1.0; 3]
}

impl Loader<'_> {
    /// The glTF default material (white, metallic 1, roughness 1), added once when needed.
    pub(super) fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.parts.materials.push(Material {
                name: "default".into(),
                reflectance: Reflectance::GltfPbr(GltfPbrParams::default()),
                emission: Vec3::ZERO,
                emission_texture: None,
                normal_map: None,
                double_sided: false,
                alpha: Alpha::OPAQUE,
                road: false,
            });
            (self.parts.materials.len() - 1) as u32
        })
    }

    pub(super) fn material(
        &mut self,
        m: &gltf::Material,
        index: usize,
        document: &gltf::Document,
    ) -> Result<Material, SceneError> {
        let name = m
            .name()
            .map_or_else(|| format!("material{index}"), str::to_string);
        let element = format!("material {name:?} ({index})");
        validate::material(m).map_err(|r| self.bad(&element, r))?;
        let pbr = m.pbr_metallic_roughness();
        let base_color_texture = match pbr.base_color_texture() {
            Some(info) => self.texture(&info, ColorSpace::Srgb, &element)?,
            None => None,
        };
        let mr_texture = match pbr.metallic_roughness_texture() {
            Some(info) => self.texture(&info, ColorSpace::Linear, &element)?,
            None => None,
        };
        let emission_texture = match m.emissive_texture() {
            Some(info) => self.texture(&info, ColorSpace::Srgb, &element)?,
            None => None,
        };
        let normal_map = match m.normal_texture() {
            Some(info) => {
                let scale = info.scale();
                if !scale.is_finite() {
                    return Err(
                        self.bad(element, format!("normalTexture.scale {scale} is invalid"))
                    );
                }
                let transform = info
                    .extension_value("KHR_texture_transform")
                    .map(UvTransform::from_json)
                    .transpose()
                    .map_err(|e| self.bad(format!("{element}, normalTexture"), e))?;
                let texture = self.texture_of(
                    &info.texture(),
                    info.tex_coord(),
                    transform,
                    ColorSpace::Linear,
                    &element,
                )?;
                texture.map(|texture| NormalMap { texture, scale })
            }
            None => None,
        };
        if m.occlusion_texture().is_some() {
            let without = "ignored: the path tracer computes occlusion itself";
            self.warn("occlusionTexture", "material", &element, without);
        }
        let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        if !emission.is_finite() || emission.min_element() < 0.0 {
            return Err(self.bad(element, format!("emission {emission} is invalid")));
        }
        let base = Vec4::from(pbr.base_color_factor());
        let mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => {
                let cutoff = m.alpha_cutoff().unwrap_or(0.5);
                if !cutoff.is_finite() {
                    return Err(self.bad(element, format!("alphaCutoff {cutoff} is invalid")));
                }
                AlphaMode::Mask { cutoff }
            }
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        let alpha = match mode {
            AlphaMode::Opaque => Alpha::OPAQUE,
            mode => Alpha {
                mode,
                factor: base.w,
                texture: base_color_texture,
            },
        };
        let extras = self.streaks_extras(m, &element)?;
        let road = extras.as_ref().is_some_and(|x| x.road);
        if m.extension_value("KHR_materials_unlit").is_some() {
            // Seen as its base colour: an emitter of that radiance that reflects nothing.
            return Ok(Material {
                name,
                reflectance: Reflectance::Unlit,
                emission: base.truncate(),
                emission_texture: base_color_texture,
                normal_map: None,
                double_sided: m.double_sided(),
                alpha,
                road,
            });
        }
        let reflectance = match extras.filter(|x| x.bsdf.is_some()) {
            Some(x) => self.paper(x, base_color_texture, mr_texture, &element)?,
            None => {
                let specular = self.specular(m, &element)?;
                let sheen = self.sheen(m, document, &element)?;
                let film = self.iridescence(m, document, &element)?;
                let clearcoat = self.clearcoat(m, document, &element)?;
                let transmission = self.transmission(m, document, &element)?;
                let volume = self.volume(m, document, &element)?;
                Reflectance::GltfPbr(GltfPbrParams {
                    base_color: base.truncate(),
                    base_color_texture,
                    metallic: pbr.metallic_factor(),
                    roughness: pbr.roughness_factor(),
                    metallic_roughness_texture: mr_texture,
                    specular: specular.factor,
                    specular_texture: specular.texture,
                    specular_color: specular.color,
                    specular_color_texture: specular.color_texture,
                    ior: specular.ior,
                    sheen_color: Vec3::from(sheen.sheen_color_factor),
                    sheen_color_texture: sheen.color_texture,
                    sheen_roughness: sheen.sheen_roughness_factor,
                    sheen_roughness_texture: sheen.roughness_texture,
                    iridescence: film.iridescence_factor,
                    iridescence_texture: film.texture,
                    iridescence_ior: film.iridescence_ior,
                    iridescence_thickness: [
                        film.iridescence_thickness_minimum,
                        film.iridescence_thickness_maximum,
                    ],
                    iridescence_thickness_texture: film.thickness_texture,
                    clearcoat: clearcoat.clearcoat_factor,
                    clearcoat_texture: clearcoat.texture,
                    clearcoat_roughness: clearcoat.clearcoat_roughness_factor,
                    clearcoat_roughness_texture: clearcoat.roughness_texture,
                    clearcoat_normal_map: clearcoat.normal_map,
                    transmission: transmission.transmission_factor,
                    transmission_texture: transmission.texture,
                    volume,
                })
            }
        };
        Ok(Material {
            name,
            reflectance,
            emission,
            emission_texture,
            normal_map,
            double_sided: m.double_sided(),
            alpha,
            road,
        })
    }

    /// KHR_materials_specular and KHR_materials_ior of a glTF material, with their defaults
    /// where absent (specular 1, specular colour 1, ior 1.5); out-of-range values are errors.
    pub(super) fn specular(
        &mut self,
        m: &gltf::Material,
        element: &str,
    ) -> Result<Specular, SceneError> {
        let ior = m.ior().unwrap_or(1.5);
        if !(ior == 0.0 || (ior.is_finite() && ior >= 1.0)) {
            return Err(self.bad(
                element,
                format!("KHR_materials_ior: ior {ior} must be 0 or at least 1"),
            ));
        }
        let Some(sp) = m.specular() else {
            return Ok(Specular {
                factor: 1.0,
                texture: None,
                color: Vec3::ONE,
                color_texture: None,
                ior,
            });
        };
        let (factor, color) = (sp.specular_factor(), Vec3::from(sp.specular_color_factor()));
        self.unit_factor(
            ("KHR_materials_specular", "specularFactor"),
            factor,
            element,
        )?;
        if !(color.is_finite() && color.min_element() >= 0.0) {
            return Err(self.bad(
                element,
                format!("KHR_materials_specular: specularColorFactor {color} is invalid"),
            ));
        }
        let texture = match sp.specular_texture() {
            Some(info) => self.texture(&info, ColorSpace::Linear, element)?,
            None => None,
        };
        let color_texture = match sp.specular_color_texture() {
            Some(info) => self.texture(&info, ColorSpace::Srgb, element)?,
            None => None,
        };
        Ok(Specular {
            factor,
            texture,
            color,
            color_texture,
            ior,
        })
    }

    /// KHR_materials_clearcoat of a glTF material (no coat where absent), read from the JSON
    /// (the gltf crate does not know the extension); its textures are decoded, the
    /// clearcoatNormalTexture as the coat's own normal map.
    pub(super) fn clearcoat(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Clearcoat, SceneError> {
        const NAME: &str = "KHR_materials_clearcoat";
        let Some(mut c) = self.material_extension::<Clearcoat>(m, NAME, element)? else {
            return Ok(Clearcoat::default());
        };
        self.unit_factor((NAME, "clearcoatFactor"), c.clearcoat_factor, element)?;
        let roughness = c.clearcoat_roughness_factor;
        self.unit_factor((NAME, "clearcoatRoughnessFactor"), roughness, element)?;
        if let Some(n) = c.clearcoat_normal_texture {
            if !n.scale.is_finite() {
                let why = format!(
                    "{NAME}: clearcoatNormalTexture.scale {} is invalid",
                    n.scale
                );
                return Err(self.bad(element, why));
            }
            let key = (NAME, "clearcoatNormalTexture");
            c.normal_map = self
                .extension_texture(document, key, Some(n.info), element)?
                .map(|texture| NormalMap {
                    texture,
                    scale: n.scale,
                });
        }
        let (info, key) = (c.clearcoat_texture, (NAME, "clearcoatTexture"));
        c.texture = self.extension_texture(document, key, info, element)?;
        let (info, key) = (
            c.clearcoat_roughness_texture,
            (NAME, "clearcoatRoughnessTexture"),
        );
        c.roughness_texture = self.extension_texture(document, key, info, element)?;
        Ok(c)
    }

    /// KHR_materials_sheen of a glTF material (none: black sheen, no layer), with its
    /// textures (the colour sRGB, the roughness linear); a colour channel or the roughness
    /// outside [0, 1] is an error.
    pub(super) fn sheen(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Sheen, SceneError> {
        const NAME: &str = "KHR_materials_sheen";
        let Some(mut sh) = self.material_extension::<Sheen>(m, NAME, element)? else {
            return Ok(Sheen::default());
        };
        for c in sh.sheen_color_factor {
            self.unit_factor((NAME, "sheenColorFactor"), c, element)?;
        }
        let roughness = sh.sheen_roughness_factor;
        self.unit_factor((NAME, "sheenRoughnessFactor"), roughness, element)?;
        let (info, key) = (sh.sheen_color_texture, (NAME, "sheenColorTexture"));
        sh.color_texture =
            self.extension_texture_in(document, key, info, ColorSpace::Srgb, element)?;
        let (info, key) = (sh.sheen_roughness_texture, (NAME, "sheenRoughnessTexture"));
        sh.roughness_texture = self.extension_texture(document, key, info, element)?;
        Ok(sh)
    }

    /// KHR_materials_iridescence of a glTF material (none: iridescence 0), with its textures;
    /// a factor outside [0, 1], an index below 1 or a negative or non-finite thickness is an
    /// error.
    pub(super) fn iridescence(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Iridescence, SceneError> {
        const NAME: &str = "KHR_materials_iridescence";
        let Some(mut f) = self.material_extension::<Iridescence>(m, NAME, element)? else {
            return Ok(Iridescence::default());
        };
        self.unit_factor((NAME, "iridescenceFactor"), f.iridescence_factor, element)?;
        if !(f.iridescence_ior.is_finite() && f.iridescence_ior >= 1.0) {
            let why = format!(
                "{NAME}: iridescenceIor {} must be at least 1",
                f.iridescence_ior
            );
            return Err(self.bad(element, why));
        }
        for (key, d) in [
            (
                "iridescenceThicknessMinimum",
                f.iridescence_thickness_minimum,
            ),
            (
                "iridescenceThicknessMaximum",
                f.iridescence_thickness_maximum,
            ),
        ] {
            if !(d.is_finite() && d >= 0.0) {
                let why = format!("{NAME}: {key} {d} must be finite and not negative");
                return Err(self.bad(element, why));
            }
        }
        let (info, key) = (f.iridescence_texture, (NAME, "iridescenceTexture"));
        f.texture = self.extension_texture(document, key, info, element)?;
        let (info, key) = (
            f.iridescence_thickness_texture,
            (NAME, "iridescenceThicknessTexture"),
        );
        f.thickness_texture = self.extension_texture(document, key, info, element)?;
        Ok(f)
    }

    /// KHR_materials_transmission of a glTF material (none: transmission 0), with its texture;
    /// a factor outside [0, 1] is an error.
    pub(super) fn transmission(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Transmission, SceneError> {
        const NAME: &str = "KHR_materials_transmission";
        let Some(mut t) = self.material_extension::<Transmission>(m, NAME, element)? else {
            return Ok(Transmission::default());
        };
        self.unit_factor((NAME, "transmissionFactor"), t.transmission_factor, element)?;
        let (info, key) = (t.transmission_texture, (NAME, "transmissionTexture"));
        t.texture = self.extension_texture(document, key, info, element)?;
        Ok(t)
    }

    /// KHR_materials_volume of a glTF material: `None` (thin-walled, as the extension says)
    /// without it or with thicknessFactor 0; out-of-range values are errors. A
    /// thicknessTexture is validated (its index names a texture; the texture info and its
    /// KHR_texture_transform are well formed and finite) and not used: the extension says
    /// that ray tracers should ignore it and use the distance the ray travels inside, which
    /// the path tracer measures.
    pub(super) fn volume(
        &mut self,
        m: &gltf::Material,
        document: &gltf::Document,
        element: &str,
    ) -> Result<Option<Volume>, SceneError> {
        let Some(v) = self.material_extension::<JsonVolume>(m, "KHR_materials_volume", element)?
        else {
            return Ok(None);
        };
        let reason = |r: String| format!("KHR_materials_volume: {r}");
        let colour = Vec3::from(v.attenuation_color);
        if !(v.thickness_factor.is_finite() && v.thickness_factor >= 0.0) {
            let why = format!("thicknessFactor {} is invalid", v.thickness_factor);
            return Err(self.bad(element, reason(why)));
        }
        if v.attenuation_distance.is_nan() || v.attenuation_distance <= 0.0 {
            let why = format!(
                "attenuationDistance {} must be positive",
                v.attenuation_distance
            );
            return Err(self.bad(element, reason(why)));
        }
        if !(colour.is_finite() && colour.min_element() >= 0.0 && colour.max_element() <= 1.0) {
            let why = format!("attenuationColor {colour} is not in [0, 1]");
            return Err(self.bad(element, reason(why)));
        }
        if let Some(t) = v.thickness_texture {
            if document.textures().nth(t.index).is_none() {
                let why = format!("thicknessTexture: texture {} does not exist", t.index);
                return Err(self.bad(element, reason(why)));
            }
            if t.transform.is_some_and(|t| !t.is_finite()) {
                let why = "thicknessTexture: KHR_texture_transform has a non-finite offset, \
                           rotation or scale";
                return Err(self.bad(element, reason(why.into())));
            }
        }
        if v.thickness_factor == 0.0 {
            return Ok(None);
        }
        Ok(Some(Volume::new(
            v.thickness_factor,
            colour,
            v.attenuation_distance,
        )))
    }

    /// Extension `name` of material `m` as the JSON has it, parsed as `T`; `None` where the
    /// material does not use it. The gltf crate does not know the extensions read this way;
    /// a malformed object is an error naming the material and the extension.
    fn material_extension<T: DeserializeOwned>(
        &self,
        m: &gltf::Material,
        name: &str,
        element: &str,
    ) -> Result<Option<T>, SceneError> {
        m.extension_value(name)
            .map(|value| {
                serde_json::from_value(value.clone())
                    .map_err(|e| self.bad(element, format!("{name}: {e}")))
            })
            .transpose()
    }

    /// Checks that `value`, the factor `key` of material extension `extension`, is in
    /// [0, 1]; otherwise an error naming the material, the extension and the factor.
    fn unit_factor(
        &self,
        (extension, key): (&str, &str),
        value: f32,
        element: &str,
    ) -> Result<(), SceneError> {
        if (0.0..=1.0).contains(&value) {
            return Ok(());
        }
        let why = format!("{extension}: {key} {value} is not in [0, 1]");
        Err(self.bad(element, why))
    }

    /// The texture `info` names, the textureInfo `key` of material extension `extension`
    /// (`None` without one), decoded as linear data, which most textures these extensions
    /// name are; an index past the file's textures is an error naming the material, the
    /// extension and the key.
    fn extension_texture(
        &mut self,
        document: &gltf::Document,
        key: (&str, &str),
        info: Option<JsonTextureInfo>,
        element: &str,
    ) -> Result<Option<TextureRef>, SceneError> {
        self.extension_texture_in(document, key, info, ColorSpace::Linear, element)
    }

    /// [`Loader::extension_texture`] decoded in colour space `space` (sRGB for a colour).
    fn extension_texture_in(
        &mut self,
        document: &gltf::Document,
        (extension, key): (&str, &str),
        info: Option<JsonTextureInfo>,
        space: ColorSpace,
        element: &str,
    ) -> Result<Option<TextureRef>, SceneError> {
        let Some(info) = info else {
            return Ok(None);
        };
        let Some(texture) = document.textures().nth(info.index) else {
            let why = format!("{extension}: {key}: texture {} does not exist", info.index);
            return Err(self.bad(element, why));
        };
        self.texture_of(&texture, info.tex_coord, info.transform, space, element)
    }

    pub(super) fn streaks_extras(
        &self,
        m: &gltf::Material,
        element: &str,
    ) -> Result<Option<StreaksExtras>, SceneError> {
        let Some(raw) = m.extras() else {
            return Ok(None);
        };
        let value: serde_json::Value = serde_json::from_str(raw.get())
            .map_err(|e| self.bad(element, format!("extras: {e}")))?;
        let Some(streaks) = value.get("streaks") else {
            return Ok(None);
        };
        let x: StreaksExtras = serde_json::from_value(streaks.clone())
            .map_err(|e| self.bad(element, format!("extras.streaks: {e}")))?;
        let paper_keys = [
            ("kd", x.kd.is_some()),
            ("ks", x.ks.is_some()),
            ("alpha", x.alpha.is_some()),
            ("shininess", x.shininess.is_some()),
            ("alpha_dry", x.alpha_dry.is_some()),
            ("ks_dry", x.ks_dry.is_some()),
            ("kr", x.kr.is_some()),
            ("retro_width", x.retro_width.is_some()),
        ];
        if x.bsdf.is_none() {
            if let Some((key, _)) = paper_keys.iter().find(|(_, given)| *given) {
                return Err(self.bad(
                    element,
                    format!(
                        "extras.streaks: {key:?} needs \"bsdf\" (\"ggx\", \"ward\" or \"blinn_phong\"); \
                         without it only \"road\" may be given"
                    ),
                ));
            }
        }
        Ok(Some(x))
    }

    pub(super) fn paper(
        &self,
        x: StreaksExtras,
        kd_texture: Option<TextureRef>,
        mr_texture: Option<TextureRef>,
        element: &str,
    ) -> Result<Reflectance, SceneError> {
        let bad = |reason: String| self.bad(element, format!("extras.streaks: {reason}"));
        let colour = |c: Option<[f32; 3]>, key: &str| {
            let v = Vec3::from(c.unwrap_or([0.0; 3]));
            if v.is_finite() && v.min_element() >= 0.0 {
                Ok(v)
            } else {
                Err(bad(format!("{key} {v} must be finite and non-negative")))
            }
        };
        let kd = colour(x.kd, "kd")?;
        let ks = colour(x.ks, "ks")?;
        let ks_dry = colour(x.ks_dry.or(x.ks), "ks_dry")?;
        let Some(bsdf) = x.bsdf else {
            return Err(bad("no \"bsdf\"".into()));
        };
        let model = match bsdf {
            StreaksBsdf::Ggx => PaperModel::Ggx,
            StreaksBsdf::Ward => PaperModel::Ward,
            StreaksBsdf::BlinnPhong => PaperModel::BlinnPhong,
        };
        let (alpha, shininess) = match model {
            PaperModel::Ggx | PaperModel::Ward => match x.alpha {
                Some(a) if a.is_finite() && a > 0.0 => (a, 0.0),
                Some(a) => return Err(bad(format!("alpha {a} must be positive"))),
                None => return Err(bad(format!("{model:?} needs \"alpha\""))),
            },
            PaperModel::BlinnPhong => match x.shininess {
                Some(s) if s.is_finite() && s >= 0.0 => (0.0, s),
                Some(s) => return Err(bad(format!("shininess {s} must be non-negative"))),
                None => return Err(bad("blinn_phong needs \"shininess\"".into())),
            },
        };
        let retro = match (x.kr, x.retro_width) {
            (None, None) => None,
            (None, Some(_)) => return Err(bad("retro_width needs \"kr\"".into())),
            (Some(_), _) if model != PaperModel::Ggx => {
                return Err(bad(format!(
                    "kr (glass beads) is only for \"ggx\", not {model:?}"
                )));
            }
            (Some(kr), width) => {
                let kr = colour(Some(kr), "kr")?;
                let width = width.unwrap_or(crate::bsdf::BEAD_CONE_WIDTH);
                if !(width.is_finite() && width > 0.0 && width <= 1.0) {
                    return Err(bad(format!(
                        "retro_width {width} must be in (0, 1] radians"
                    )));
                }
                if kr.max_element() > 1.0 {
                    return Err(bad(format!(
                        "kr {kr} must be at most 1 (the cone's albedo)"
                    )));
                }
                Some(Retro {
                    kr,
                    exponent: crate::bsdf::Retroreflective::exponent_for_width(width),
                })
            }
        };
        let wetness = match x.alpha_dry {
            None => None,
            Some(a)
                if !(a.is_finite() && a >= 0.0)
                    || (a == 0.0 && model != PaperModel::BlinnPhong) =>
            {
                return Err(bad(format!("alpha_dry {a} is invalid")));
            }
            Some(alpha_dry) => {
                let Some(texture) = mr_texture else {
                    return Err(bad(
                        "alpha_dry needs a metallicRoughnessTexture (the dryness map)".into(),
                    ));
                };
                Some(Wetness {
                    texture,
                    alpha_dry,
                    ks_dry,
                })
            }
        };
        Ok(Reflectance::Paper {
            model,
            kd,
            ks,
            alpha,
            shininess,
            kd_texture,
            wetness,
            retro,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_docs::{error, load_err, png_file, rejects, test_doc, write_embedded};

    use crate::bsdf::Bsdf;
    use crate::geometry::VertexAttributes;
    use crate::material::{GltfPbrParams, Reflectance};
    use crate::scene::Scene;
    use glam::{Vec2, Vec3};
    use serde_json::json;

    /// KHR_materials_unlit (required by the file): the camera sees the base colour times the
    /// vertex colour, exactly, whatever the lights; the surface reflects nothing.
    #[test]
    fn unlit_pixels_are_the_base_colour() {
        use super::super::test_docs::Doc;
        use crate::integrator::{render, Layers, RenderJob};
        use streaks_settings::RenderSettings;
        let mut d = Doc::default();
        // A quad of side 4 in z = 0 facing +Z, COLOR_0 grey 0.5; the camera 1 m in front.
        let pos = d.floats(
            &[-2., -2., 0., 2., -2., 0., 2., 2., 0., -2., 2., 0.],
            "VEC3",
            3,
        );
        let col = d.floats(&[0.5, 0.5, 0.5].repeat(4), "VEC3", 3);
        let idx = d.indices(&[0, 1, 2, 0, 2, 3]);
        let base = [1.0, 0.217_637_64, 0.0];
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_unlit", "KHR_lights_punctual"],
            "extensionsRequired": ["KHR_materials_unlit"],
            "scenes": [{"nodes": [0, 1, 2]}],
            "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 1]},
                {"translation": [0, 0, 0.5], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": pos, "COLOR_0": col},
                "indices": idx, "material": 0}]}],
            "materials": [{"name": "orange", "emissiveFactor": [1, 1, 1],
                "pbrMetallicRoughness": {"baseColorFactor": [base[0], base[1], base[2], 1]},
                "extensions": {"KHR_materials_unlit": {}}}],
            "cameras": [{"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}}],
            "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1e5}]}},
            "buffers": [{"byteLength": d.bin.len()}],
            "bufferViews": d.views,
            "accessors": d.accessors
        });
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &d.bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        assert_eq!(scene.materials[0].reflectance, Reflectance::Unlit);
        let expected = Vec3::from(base) * 0.5;
        for max_depth in [1, 8] {
            let job = RenderJob {
                width: 6,
                height: 4,
                seed: 1,
                layers: Layers::default(),
                settings: RenderSettings::new(4, max_depth),
                motion: Default::default(),
            };
            let out = render(&scene, scene.camera(None).unwrap(), &job, &|_| {});
            for p in &out.image.pixels {
                assert!(
                    (*p - expected).abs().max_element() < 1e-5,
                    "{p} vs {expected}"
                );
            }
        }
    }

    #[test]
    fn road_materials_are_flagged_with_or_without_a_paper_model() {
        let dir = tempfile::tempdir().unwrap();
        let (doc, bin) = test_doc();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        assert!(scene.materials.iter().all(|m| !m.road));
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["road"] = json!(true);
        // A glTF metallic-roughness material may carry the flag alone.
        doc["materials"][1]["extras"] = json!({"streaks": {"road": true}});
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let asphalt = &scene.materials[0];
        assert!(asphalt.road);
        assert!(matches!(asphalt.reflectance, Reflectance::Paper { .. }));
        assert!(scene.materials[1].road);
        assert!(matches!(
            scene.materials[1].reflectance,
            Reflectance::GltfPbr(_)
        ));
        // Paper parameters without a model are an error that says what is missing.
        let (mut doc, bin) = test_doc();
        doc["materials"][1]["extras"] = json!({"streaks": {"road": true, "alpha": 0.1}});
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"glow\" (1)") && err.contains("needs \"bsdf\""),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["road"] = json!("yes");
        let err = load_err(doc, &bin);
        assert!(err.contains("extras.streaks"), "{err}");
    }

    #[test]
    fn bad_materials_and_cameras_are_named() {
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["bsdf"] = json!("phong");
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"asphalt\" (0)") && err.contains("phong"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["alpha"] = json!(-1);
        let err = load_err(doc, &bin);
        assert!(
            err.contains("material \"asphalt\" (0)") && err.contains("alpha"),
            "{err}"
        );
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["alpha_dry"] = json!(0.3);
        let err = load_err(doc, &bin);
        assert!(err.contains("metallicRoughnessTexture"), "{err}");
    }

    /// `kr` gives a ggx material glass beads (bead paint), with the cone's width from
    /// `retro_width`; bad values and other models are errors that say why.
    #[test]
    fn glass_beads_make_bead_paint() {
        let (mut doc, bin) = test_doc();
        doc["materials"][0]["extras"]["streaks"]["kr"] = json!([0.002, 0.002, 0.0015]);
        doc["materials"][0]["extras"]["streaks"]["retro_width"] = json!(0.02);
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let at = VertexAttributes::from_uv(Vec2::new(0.5, 0.5));
        let crate::bsdf::Bsdf::Retroreflective(paint) =
            scene.materials[0].bsdf_at(&at, &scene.textures)
        else {
            panic!("not bead paint")
        };
        assert_eq!(paint.kr, Vec3::new(0.002, 0.002, 0.0015));
        assert!((paint.exponent - 2500.0).abs() < 0.5, "{}", paint.exponent);
        assert_eq!(paint.alpha, 0.05);
        let paper = "/materials/0/extras/streaks";
        rejects(&[
            (
                "/materials/0/extras/streaks/kr",
                json!([0.1, -0.1, 0.1]),
                &["asphalt", "kr", "non-negative"],
            ),
            (
                "/materials/0/extras/streaks/kr",
                json!([2.0, 0.1, 0.1]),
                &["asphalt", "kr", "at most 1"],
            ),
            (
                "/materials/0/extras/streaks/retro_width",
                json!(0.1),
                &["asphalt", "retro_width needs \"kr\""],
            ),
            (
                paper,
                json!({"bsdf": "ward", "alpha": 0.1, "kr": [0.01, 0.01, 0.01]}),
                &["asphalt", "only for \"ggx\""],
            ),
            (
                paper,
                json!({"bsdf": "ggx", "alpha": 0.1, "kr": [0.01, 0.01, 0.01], "retro_width": 0}),
                &["asphalt", "retro_width 0"],
            ),
        ]);
    }

    #[test]
    fn wet_dry_material_reads_the_dryness_map() {
        // A 2x1 PNG: left texel G = 0 (wet), right texel G = 255 (dry).
        let dir = png_file("dry.png", 2, 1, vec![0, 0, 0, 255, 0, 255, 0, 255]);
        let (mut doc, bin) = test_doc();
        doc["images"] = json!([{"uri": "dry.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][0]["pbrMetallicRoughness"] =
            json!({"metallicRoughnessTexture": {"index": 0}});
        doc["materials"][0]["extras"]["streaks"]["alpha_dry"] = json!(0.45);
        doc["materials"][0]["extras"]["streaks"]["ks_dry"] = json!([0.1, 0.1, 0.1]);
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert_eq!(scene.textures.len(), 1);
        let m = &scene.materials[0];
        let crate::bsdf::Bsdf::Ggx(wet) = m.bsdf_at(
            &VertexAttributes::from_uv(Vec2::new(0.25, 0.5)),
            &scene.textures,
        ) else {
            panic!("not ggx")
        };
        let crate::bsdf::Bsdf::Ggx(dry) = m.bsdf_at(
            &VertexAttributes::from_uv(Vec2::new(0.75, 0.5)),
            &scene.textures,
        ) else {
            panic!("not ggx")
        };
        assert!((wet.alpha - 0.05).abs() < 1e-6 && (dry.alpha - 0.45).abs() < 1e-6);
        assert!((dry.ks.x - 0.1).abs() < 1e-6);
        // A missing image names the material, the image and the file.
        std::fs::remove_file(dir.path().join("dry.png")).unwrap();
        let err = Scene::load(&write_embedded(dir.path(), doc, &bin))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("material \"asphalt\" (0), image 0") && err.contains("dry.png"),
            "{err}"
        );
    }

    #[test]
    fn plain_material_has_the_extensions_defaults() {
        let (doc, bin) = test_doc();
        let dir = tempfile::tempdir().unwrap();
        let scene = Scene::load(&write_embedded(dir.path(), doc, &bin)).unwrap();
        let Reflectance::GltfPbr(g) = &scene.materials[1].reflectance else {
            panic!("glow is not a glTF material")
        };
        let defaults = GltfPbrParams {
            base_color: g.base_color,
            ..GltfPbrParams::default()
        };
        assert_eq!(*g, defaults);
    }

    #[test]
    fn iridescence_is_read_with_its_textures() {
        // One texel: R 255, G 128, B 0, A 64.
        let dir = png_file("t.png", 1, 1, vec![255, 128, 0, 64]);
        let (mut doc, bin) = test_doc();
        doc["extensionsRequired"] = json!(["KHR_materials_iridescence"]);
        doc["extensionsUsed"]
            .as_array_mut()
            .unwrap()
            .push(json!("KHR_materials_iridescence"));
        doc["images"] = json!([{"uri": "t.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["extensions"]["KHR_materials_iridescence"] = json!({
            "iridescenceFactor": 0.5, "iridescenceTexture": {"index": 0},
            "iridescenceIor": 1.8, "iridescenceThicknessMinimum": 200,
            "iridescenceThicknessMaximum": 600, "iridescenceThicknessTexture": {"index": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(
            &crate::geometry::VertexAttributes::from_uv(Vec2::ZERO),
            &scene.textures,
        ) else {
            panic!("not a glTF material")
        };
        assert_eq!((g.iridescence, g.iridescence_ior), (0.5, 1.8));
        let want = 200.0 + 400.0 * 128.0 / 255.0;
        assert!((g.iridescence_thickness - want).abs() < 1e-3, "{g:?}");
        for (value, what) in [
            (json!({"iridescenceIor": 0.5}), "iridescenceIor 0.5"),
            (
                json!({"iridescenceThicknessMaximum": -1}),
                "iridescenceThicknessMaximum -1",
            ),
            (json!({"iridescenceFactor": 2}), "iridescenceFactor 2"),
        ] {
            let mut d = doc.clone();
            d["materials"][1]["extensions"] = json!({ "KHR_materials_iridescence": value });
            let err = Scene::load(&write_embedded(dir.path(), d, &bin))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("material \"glow\" (1)") && err.contains(what),
                "{err}"
            );
        }
    }

    #[test]
    fn sheen_is_read_with_its_textures() {
        // One texel: R 255, G 128, B 0, A 64.
        let dir = png_file("t.png", 1, 1, vec![255, 128, 0, 64]);
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"]
            .as_array_mut()
            .unwrap()
            .push(json!("KHR_materials_sheen"));
        doc["images"] = json!([{"uri": "t.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["extensions"]["KHR_materials_sheen"] = json!({
            "sheenColorFactor": [0.9, 0.5, 1.0], "sheenColorTexture": {"index": 0},
            "sheenRoughnessFactor": 0.8, "sheenRoughnessTexture": {"index": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        // Decoded twice: sRGB (colour) and linear (roughness).
        assert_eq!(scene.textures.len(), 2);
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(
            &crate::geometry::VertexAttributes::from_uv(Vec2::ZERO),
            &scene.textures,
        ) else {
            panic!("not a glTF material")
        };
        // sRGB 128/255 is linear 0.2158; the roughness is the texel's alpha.
        let want = Vec3::new(0.9, 0.5 * 0.2158, 0.0);
        assert!((g.sheen_color - want).abs().max_element() < 1e-3, "{g:?}");
        assert!(
            (g.sheen_roughness - 0.8 * 64.0 / 255.0).abs() < 1e-4,
            "{g:?}"
        );
        // Out of range: errors naming the material and the factor.
        for (value, what) in [
            (
                json!({"sheenColorFactor": [1.5, 0, 0]}),
                "sheenColorFactor 1.5",
            ),
            (
                json!({"sheenRoughnessFactor": -0.1}),
                "sheenRoughnessFactor -0.1",
            ),
            (json!({"sheenColorTexture": {"index": 3}}), "texture 3"),
        ] {
            let mut d = doc.clone();
            d["materials"][1]["extensions"] = json!({ "KHR_materials_sheen": value });
            let err = Scene::load(&write_embedded(dir.path(), d, &bin))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("material \"glow\" (1)") && err.contains(what),
                "{err}"
            );
        }
    }

    #[test]
    fn specular_ior_and_clearcoat_are_read_with_their_textures() {
        // One texel: R 255, G 128, B 0, A 64.
        let dir = png_file("t.png", 1, 1, vec![255, 128, 0, 64]);
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!([
            "KHR_lights_punctual",
            "KHR_materials_emissive_strength",
            "KHR_materials_specular",
            "KHR_materials_ior",
            "KHR_materials_clearcoat"
        ]);
        doc["images"] = json!([{"uri": "t.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["extensions"]["KHR_materials_specular"] = json!({
            "specularFactor": 0.5, "specularTexture": {"index": 0},
            "specularColorFactor": [2, 1, 0.5], "specularColorTexture": {"index": 0}});
        doc["materials"][1]["extensions"]["KHR_materials_ior"] = json!({"ior": 1.33});
        doc["materials"][1]["extensions"]["KHR_materials_clearcoat"] = json!({
            "clearcoatFactor": 0.8, "clearcoatTexture": {"index": 0},
            "clearcoatRoughnessFactor": 0.2, "clearcoatRoughnessTexture": {"index": 0},
            "clearcoatNormalTexture": {"index": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        // Honoured: no "uses KHR_materials_..." warning; the coat's normal map is read (the
        // uv-less triangle renders without it, as with a base normal map).
        assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
        assert!(
            scene.warnings[0].contains("mesh \"tri\" (1)")
                && scene.warnings[0].contains("rendered without the normal map"),
            "{:?}",
            scene.warnings
        );
        let coat_map = scene.materials[1]
            .coat_normal_map()
            .expect("a coat normal map");
        assert_eq!(coat_map.scale, 1.0);
        // The image decoded twice: linear (specular, clearcoat) and sRGB (specular colour).
        assert_eq!(scene.textures.len(), 2);
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(
            &crate::geometry::VertexAttributes::from_uv(Vec2::ZERO),
            &scene.textures,
        ) else {
            panic!("not a glTF material")
        };
        let close = |a: f32, b: f32| (a - b).abs() < 1e-4;
        assert!(close(g.specular, 0.5 * 64.0 / 255.0), "{g:?}");
        // sRGB 128/255 is linear 0.2158.
        assert!(
            (g.specular_color - Vec3::new(2.0, 0.2158, 0.0))
                .abs()
                .max_element()
                < 1e-3,
            "{g:?}"
        );
        assert_eq!(g.ior, 1.33);
        assert!(close(g.clearcoat, 0.8), "{g:?}");
        assert!(close(g.clearcoat_roughness, 0.2 * 128.0 / 255.0), "{g:?}");
        // Defaults inside the extensions: an empty clear coat is no coat, an empty specular
        // is the default strength and colour; ior 0 is allowed.
        let mut d = doc.clone();
        d["materials"][1]["extensions"] = json!({
            "KHR_materials_specular": {}, "KHR_materials_clearcoat": {},
            "KHR_materials_ior": {"ior": 0}});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(
            &crate::geometry::VertexAttributes::from_uv(Vec2::ZERO),
            &scene.textures,
        ) else {
            panic!("not a glTF material")
        };
        assert_eq!((g.specular, g.specular_color, g.ior), (1.0, Vec3::ONE, 0.0));
        assert_eq!((g.clearcoat, g.clearcoat_roughness), (0.0, 0.0));
        // Out of range: errors naming the material and the extension.
        for (ext, value, what) in [
            ("KHR_materials_ior", json!({"ior": 0.5}), "ior 0.5"),
            (
                "KHR_materials_clearcoat",
                json!({"clearcoatFactor": 2}),
                "clearcoatFactor 2",
            ),
            (
                "KHR_materials_clearcoat",
                json!({"clearcoatTexture": {"index": 7}}),
                "texture 7",
            ),
            (
                "KHR_materials_specular",
                json!({"specularColorFactor": [1, -1, 1]}),
                "specularColorFactor",
            ),
        ] {
            let mut d = doc.clone();
            d["materials"][1]["extensions"] = json!({ ext: value });
            let err = Scene::load(&write_embedded(dir.path(), d, &bin))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("material \"glow\" (1)") && err.contains(what),
                "{ext}: {err}"
            );
        }
    }

    #[test]
    fn transmission_and_volume_are_read() {
        // One texel: R 128 (transmission x 0.502), linear.
        let dir = png_file("t.png", 1, 1, vec![128, 0, 0, 255]);
        let (mut doc, bin) = test_doc();
        doc["extensionsUsed"] = json!([
            "KHR_lights_punctual",
            "KHR_materials_emissive_strength",
            "KHR_materials_transmission",
            "KHR_materials_volume"
        ]);
        doc["images"] = json!([{"uri": "t.png"}]);
        doc["textures"] = json!([{"source": 0}]);
        doc["materials"][1]["extensions"] = json!({
            "KHR_materials_transmission": {
                "transmissionFactor": 0.8, "transmissionTexture": {"index": 0}}});
        let at = crate::geometry::VertexAttributes::from_uv(Vec2::ZERO);
        // Thin-walled without KHR_materials_volume; no warning.
        let scene = Scene::load(&write_embedded(dir.path(), doc.clone(), &bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(&at, &scene.textures) else {
            panic!("not a glTF material")
        };
        assert!((g.transmission - 0.8 * 128.0 / 255.0).abs() < 1e-4, "{g:?}");
        assert!(g.thin_walled && scene.materials[1].volume().is_none());
        // A volume: attenuation colour and distance give sigma_a; a thicknessTexture is
        // validated and not used (no warning, no texture decoded for it).
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_volume"] = json!({
            "thicknessFactor": 0.02, "thicknessTexture": {"index": 0, "texCoord": 1},
            "attenuationDistance": 0.5, "attenuationColor": [0.5, 1.0, 0.25]});
        let textures = scene.textures.len();
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        assert!(scene.warnings.is_empty(), "{:?}", scene.warnings);
        assert_eq!(scene.textures.len(), textures);
        let v = scene.materials[1].volume().expect("a volume");
        let want = Vec3::new(0.5f32.ln(), 0.0, 0.25f32.ln()) / -0.5;
        assert!((v.sigma_a - want).abs().max_element() < 1e-5, "{v:?}");
        assert!(
            (v.transmittance(0.5) - Vec3::new(0.5, 1.0, 0.25))
                .abs()
                .max_element()
                < 1e-5
        );
        let Bsdf::GltfPbr(g) = scene.materials[1].bsdf_at(&at, &scene.textures) else {
            panic!("not a glTF material")
        };
        assert!(!g.thin_walled);
        // Thickness 0 is thin-walled, as the extension says; no attenuation by default.
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_volume"] = json!({});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        assert!(scene.materials[1].volume().is_none() && scene.warnings.is_empty());
        let mut d = doc.clone();
        d["materials"][1]["extensions"]["KHR_materials_volume"] = json!({"thicknessFactor": 1});
        let scene = Scene::load(&write_embedded(dir.path(), d, &bin)).unwrap();
        assert_eq!(scene.materials[1].volume().unwrap().sigma_a, Vec3::ZERO);
        // Out of range: errors naming the material and the value.
        for (ext, value, what) in [
            (
                "KHR_materials_transmission",
                json!({"transmissionFactor": 1.5}),
                "transmissionFactor 1.5",
            ),
            (
                "KHR_materials_transmission",
                json!({"transmissionTexture": {"index": 9}}),
                "texture 9",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessFactor": -1}),
                "thicknessFactor -1",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessFactor": 1, "thicknessTexture": {"index": 7}}),
                "thicknessTexture: texture 7 does not exist",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessTexture": {"index": 0, "extensions":
                    {"KHR_texture_transform": {"scale": [1e39, 1]}}}}),
                "thicknessTexture",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessTexture": {"texCoord": 0}}),
                "index",
            ),
            (
                "KHR_materials_volume",
                json!({"thicknessFactor": 1, "attenuationDistance": 0}),
                "attenuationDistance 0",
            ),
            (
                "KHR_materials_volume",
                json!({"attenuationColor": [2, 0, 0]}),
                "attenuationColor",
            ),
        ] {
            let mut d = doc.clone();
            d["materials"][1]["extensions"] = json!({ ext: value });
            let err = Scene::load(&write_embedded(dir.path(), d, &bin))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("material \"glow\" (1)") && err.contains(what),
                "{ext}: {err}"
            );
        }
    }

    #[test]
    fn materials_outside_the_specification_are_named() {
        let asphalt = &["material \"asphalt\" (0)"][..];
        let glow = &["material \"glow\" (1)"][..];
        rejects(&[
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"baseColorFactor": [-0.5, 0.5, 0.5, 1]}),
                &["material \"asphalt\" (0)", "baseColorFactor"],
            ),
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"baseColorFactor": [1e39, 0.5, 0.5, 1]}),
                asphalt,
            ),
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"metallicFactor": 1.5}),
                asphalt,
            ),
            (
                "/materials/0/pbrMetallicRoughness",
                json!({"roughnessFactor": -0.1}),
                asphalt,
            ),
            ("/materials/0/alphaCutoff", json!(-1), asphalt),
            ("/materials/1/emissiveFactor", json!([-1, 0, 0]), glow),
            ("/materials/1/emissiveFactor", json!([2, 0, 0]), glow),
            ("/materials/1/emissiveFactor", json!([1e39, 0, 0]), glow),
            (
                "/materials/1/extensions/KHR_materials_emissive_strength/emissiveStrength",
                json!(-5),
                &["material \"glow\" (1)", "emissiveStrength"],
            ),
            (
                "/materials/1/extensions/KHR_materials_emissive_strength/emissiveStrength",
                json!(1e39),
                glow,
            ),
            ("/materials/0/extras/streaks/kd", json!([-1, 0, 0]), asphalt),
            (
                "/materials/0/extras/streaks/ks",
                json!([1e39, 0, 0]),
                asphalt,
            ),
            ("/materials/0/extras/streaks/alpha", json!(1e39), asphalt),
        ]);
        // A negative strength is an error even where the factor is black.
        let (mut doc, bin) = test_doc();
        doc["materials"][1]["emissiveFactor"] = json!([0, 0, 0]);
        doc["materials"][1]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] =
            json!(-1);
        let err = error(doc, &bin);
        assert!(err.contains("material \"glow\" (1)"), "{err}");
    }
}
