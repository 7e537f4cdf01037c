//! `streaks figure`: draw one of the paper's figures from the model as a PNG.

use anyhow::{Context, Result};
use std::path::PathBuf;
use streaks_analysis::figures;

/// The figures this command can draw.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Name {
    /// Fig. 4: three lights and their virtual light columns (Eq. 4, h within 4 degrees).
    Fig4,
    /// Fig. 5: the half vectors h along the ground and why the columns slant.
    Fig5,
}

/// Draw a figure of the paper from the virtual light column model.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Which figure.
    #[arg(value_enum)]
    pub name: Name,
    /// The PNG file to write (written atomically).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let plot = match args.name {
        Name::Fig4 => figures::fig4(),
        Name::Fig5 => figures::fig5(),
    }
    .with_context(|| format!("computing {:?}", args.name))?;
    plot.write_png(&args.output)
        .with_context(|| format!("writing {}", args.output.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Cli {
        #[command(flatten)]
        args: Args,
    }

    #[test]
    fn arguments() {
        let a = Cli::try_parse_from(["figure", "fig5", "-o", "x.png"])
            .unwrap()
            .args;
        assert_eq!((a.name, a.output), (Name::Fig5, PathBuf::from("x.png")));
        assert!(Cli::try_parse_from(["figure", "fig9", "-o", "x.png"]).is_err());
        assert!(Cli::try_parse_from(["figure", "fig4"]).is_err());
    }

    #[test]
    fn writes_the_png_or_fails_cleanly() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fig4.png");
        run(Args {
            name: Name::Fig4,
            output: path.clone(),
        })
        .unwrap();
        assert!(image_size(&path) > 1000);
        let bad = dir.path().join("no/such/dir/fig4.png");
        let err = run(Args {
            name: Name::Fig4,
            output: bad,
        })
        .unwrap_err();
        assert!(format!("{err:#}").contains("fig4.png"));
    }

    fn image_size(p: &std::path::Path) -> u64 {
        std::fs::metadata(p).map(|m| m.len()).unwrap_or(0)
    }
}
