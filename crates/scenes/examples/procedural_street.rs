//! Writes one procedural street sample as a glTF scene, to look at or render by hand:
//! `cargo run --release -p streaks-scenes --example procedural_street -- OUT_DIR SEED INDEX
//! [CONFIG.toml]`, then `streaks stereo OUT_DIR/scene.gltf -o PAIR --baseline B`.

use anyhow::{bail, Context};
use streaks_scenes::procedural::{sample, GeneratorConfig};

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 {
        bail!("usage: procedural_street OUT_DIR SEED INDEX [CONFIG.toml]");
    }
    let seed: u64 = args[1].parse().context("SEED must be an integer")?;
    let index: u64 = args[2].parse().context("INDEX must be an integer")?;
    let config = match args.get(3) {
        Some(path) => GeneratorConfig::from_toml_file(path.as_ref())?,
        None => GeneratorConfig::default(),
    };
    let s = sample(&config, seed, index)?;
    let dir = std::path::Path::new(&args[0]);
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    s.doc.write(dir)?;
    println!(
        "{}: street {} ({}), baseline {} m, exposure {} EV, {} triangles, {} punctual lights",
        dir.join("scene.gltf").display(),
        s.street,
        s.split,
        s.baseline,
        s.exposure_ev,
        s.doc.triangle_count(),
        s.doc.light_count()
    );
    println!("{}", serde_json::to_string_pretty(&s.params)?);
    Ok(())
}
