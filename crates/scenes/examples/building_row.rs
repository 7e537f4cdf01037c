//! Writes a straight street at night lined with drawn buildings, to look at the facades and
//! their materials: `cargo run -p streaks-scenes --example building_row -- OUT_DIR SEED
//! [WETNESS]`, then `streaks render OUT_DIR/building_row.gltf -o OUT.png --width 480 --spp 64`
//! (add `--env-color 0.5,0.5,0.5` to see shapes and textures in even light).
//!
//! Six buildings on the right, five on the left, a patched asphalt road with slab sidewalks,
//! three street lamps and the default config's urban sky glow.

use anyhow::{bail, Context};
use glam::Vec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use streaks_scenes::buildings::{facade, placement, BuildingSpec, BuildingsConfig, Palette};
use streaks_scenes::gltf_writer::{Class, Doc, Light, LightKind, Material, Tag};
use streaks_scenes::mesh::Mesh;
use streaks_scenes::procedural::SkyConfig;
use streaks_scenes::surfaces::{scatter_uvs, sidewalk_material, wet_paper, Surface, Texture};

/// The road's half width and the sidewalks' width, metres.
const ROAD_HALF: f32 = 4.0;
const SIDEWALK: f32 = 3.0;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        bail!("usage: building_row OUT_DIR SEED [WETNESS]");
    }
    let seed: u64 = args[1].parse().context("SEED must be an integer")?;
    let wetness: f32 = match args.get(2) {
        Some(w) => w.parse().context("WETNESS must be a number in [0, 1]")?,
        None => 0.6,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let config = BuildingsConfig::default();
    let mut doc = Doc::new(
        "building_row",
        "A street at night lined with drawn buildings",
    );

    // Buildings: frontages of 8-20 m from z = 4 towards -Z on both sides.
    let mut rows = Vec::new();
    for side in [1.0f32, -1.0] {
        let mut z = 4.0f32;
        for _ in 0..if side > 0.0 { 6 } else { 5 } {
            let frontage = rand::Rng::random_range(&mut rng, 8.0..20.0f32);
            let spec = BuildingSpec::draw(&mut rng, &config, frontage, (0.35, 0.3, 0.6));
            rows.push((side, z - 0.5 * frontage, spec));
            z -= frontage;
        }
    }
    let specs: Vec<BuildingSpec> = rows.iter().map(|r| r.2.clone()).collect();
    let palette = Palette::new(&mut doc, &specs, seed as u32, (20.0, 150.0), wetness)?;
    let lot_x = ROAD_HALF + SIDEWALK;
    for (k, (side, z, spec)) in rows.iter().enumerate() {
        let model = facade(spec, &palette)?;
        doc.add_model(
            &format!("building_{k}"),
            &model,
            placement(*side, lot_x, *z),
            None,
        )?;
    }

    // Road and sidewalks (with puddles when wet).
    let length = 116.0;
    let asphalt = Texture::add(&mut doc, Surface::Asphalt, seed as u32 + 100)?;
    let mut road = Mesh::new();
    road.rect(
        Vec3::new(0.0, 0.0, 10.0 - 0.5 * length),
        Vec3::Z * 0.5 * length,
        Vec3::X * ROAD_HALF,
    );
    scatter_uvs(&mut road, Surface::Asphalt, 1);
    let road_mat = wet_paper(&asphalt.material("asphalt", [0.07; 3]), wetness).as_road();
    doc.add_tagged_mesh("road", &road, &road_mat, Tag::stuff(Class::Road))?;
    let slabs = Texture::add(&mut doc, Surface::Slabs, seed as u32 + 101)?;
    let walk = sidewalk_material(&mut doc, &slabs, [0.3, 0.29, 0.27], wetness, 7)?;
    let mut sidewalks = Mesh::new();
    for side in [1.0f32, -1.0] {
        // Panels of 2.5 m along the street, each with its own texture offset.
        let mut z = 10.0;
        while z > 10.0 - length {
            sidewalks.rect(
                Vec3::new(side * (ROAD_HALF + 0.5 * SIDEWALK), 0.12, z - 1.25),
                Vec3::Z * 1.25,
                Vec3::X * 0.5 * SIDEWALK,
            );
            z -= 2.5;
        }
        // The kerb's face towards the road (faces -X on the right: Z x Y).
        let c = Vec3::new(side * ROAD_HALF, 0.06, 10.0 - 0.5 * length);
        let (u, v) = (Vec3::Z * 0.5 * length, Vec3::Y * 0.06);
        if side > 0.0 {
            sidewalks.rect(c, u, v);
        } else {
            sidewalks.rect(c, v, u);
        }
    }
    scatter_uvs(&mut sidewalks, Surface::Slabs, 2);
    doc.add_tagged_mesh("sidewalks", &sidewalks, &walk, Tag::stuff(Class::Sidewalk))?;

    // Three street lamps (3000 K LED, about 12 klm) on alternate sides.
    let lamp = Material::emitter("lamp_lens", [60.0, 45.0, 30.0]);
    for (k, (side, z)) in [(1.0f32, -8.0f32), (-1.0, -30.0), (1.0, -52.0)]
        .into_iter()
        .enumerate()
    {
        let x = side * (ROAD_HALF - 0.5);
        let mut pole = Mesh::new();
        pole.cylinder(Vec3::new(side * (ROAD_HALF + 0.4), 0.12, z), 0.08, 7.9, 10);
        pole.cuboid(
            Vec3::new(x.min(side * (ROAD_HALF + 0.4)), 7.9, z - 0.05),
            Vec3::new(x.max(side * (ROAD_HALF + 0.4)), 8.0, z + 0.05),
        );
        let metal = Material::diffuse("pole", [0.05; 3]);
        doc.add_tagged_mesh(
            &format!("lamp_{k}/pole"),
            &pole,
            &metal,
            Tag::object(Class::Pole, 100 + k as u32),
        )?;
        let mut lens = Mesh::new();
        lens.rect(Vec3::new(x, 7.88, z), Vec3::X * 0.25, Vec3::Z * 0.12);
        doc.add_tagged_mesh(
            &format!("lamp_{k}/lens"),
            &lens,
            &lamp,
            Tag::object(Class::LightSource, 100 + k as u32),
        )?;
        doc.add_light(&Light {
            name: format!("lamp_{k}"),
            kind: LightKind::Spot {
                inner: 60f64.to_radians(),
                outer: 85f64.to_radians(),
            },
            color: [1.0, 0.78, 0.55],
            intensity: 300.0,
            position: Vec3::new(x, 7.85, z),
            direction: Vec3::NEG_Y,
        });
    }

    // The default config's sky glow at the middle of its range.
    let sky = SkyConfig::default();
    let glow = 0.5 * (sky.glow[0] + sky.glow[1]);
    doc.set_environment(serde_json::json!({ "color": sky.color.map(|c| c * glow) }));
    doc.add_camera(
        "driver",
        Vec3::new(1.6, 1.4, 8.0),
        Vec3::new(2.4, 2.4, -12.0),
        50.0,
        16.0 / 9.0,
    );
    // A closer look at the right-hand facades from the far lane.
    doc.add_camera(
        "facades",
        Vec3::new(-3.0, 1.6, -6.0),
        Vec3::new(7.0, 5.0, -16.0),
        55.0,
        16.0 / 9.0,
    );
    let dir = std::path::Path::new(&args[0]);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let files = doc.write(dir)?;
    let mut png_bytes = 0;
    for f in &files {
        if f.extension().is_some_and(|e| e == "png") {
            png_bytes += std::fs::metadata(f)?.len();
        }
    }
    println!(
        "{}: {} triangles, {} textures of {png_bytes} bytes",
        dir.join("building_row.gltf").display(),
        doc.triangle_count(),
        files
            .iter()
            .filter(|f| f.extension().is_some_and(|e| e == "png"))
            .count()
    );
    Ok(())
}
