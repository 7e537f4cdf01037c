//! `streaks-scenes`: regenerates the shipped glTF scenes (by default into the repository's
//! `scenes/` directory).

use anyhow::Context;
use clap::Parser;
use std::path::PathBuf;

/// Regenerate the glTF scenes shipped in scenes/.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    /// Output directory (default: the repository's scenes/ directory).
    #[arg(default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"))]
    dir: PathBuf,
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    std::fs::create_dir_all(&cli.dir)
        .with_context(|| format!("cannot create {}", cli.dir.display()))?;
    let docs = streaks_scenes::build_all().context("building the scenes")?;
    for d in &docs {
        let files = d
            .write(&cli.dir)
            .with_context(|| format!("writing into {}", cli.dir.display()))?;
        let name = files
            .first()
            .and_then(|f| f.file_name())
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default();
        println!(
            "{name}: {} triangles, {} punctual lights, {} files",
            d.triangle_count(),
            d.light_count(),
            files.len()
        );
    }
    Ok(())
}
