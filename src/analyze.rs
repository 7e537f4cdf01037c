//! `streaks analyze DIR`: the per-streak analysis of a pair written by `streaks stereo` (or a
//! photographed pair with a hand-written rig.json): streaks matched to their lights, measured
//! and predicted (Eq. 4) disparity per row, implied depths below the road, vertical objects
//! and road (Fig. 8), plots and `DIR/analysis/report.json`.

use anyhow::Result;
use std::path::PathBuf;
use streaks_analysis::lk::LkParams;
use streaks_analysis::report::AnalyzeParams;
use streaks_image::{ImageError, NamedRegion};

/// Analyse a rendered stereo pair: streak disparities against the virtual light column model.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The folder written by `streaks stereo` (left/right .exr or .png, rig.json, ground truth).
    pub dir: PathBuf,
    /// A region to measure as well, `name=x0,y0,x1,y1` (pixels, half-open); repeatable.
    #[arg(long = "region", value_parser = parse_named_region)]
    pub regions: Vec<NamedRegion>,
    /// How many thin vertical objects (poles) to pick from the ground-truth depth.
    #[arg(long, default_value_t = 3)]
    pub objects: usize,
    /// Rows of a region whose LK match has a lower NCC are left out of its RMS against the
    /// ground truth (and counted in the report).
    #[arg(long, default_value_t = 0.8, allow_negative_numbers = true)]
    pub min_ncc: f32,
    /// LK window width in pixels (odd).
    #[arg(long, default_value_t = 21)]
    pub window: usize,
    /// LK window height in rows (odd; still one estimate per row). 5 rows average out the
    /// Monte Carlo noise of a night render; on the clean Fig. 6 pair 1 and 5 agree.
    #[arg(long, default_value_t = 5)]
    pub rows: usize,
    /// Horizon row for the streak detector [default: from rig.json].
    #[arg(long)]
    pub horizon: Option<f32>,
    /// Farthest a light's mirror image may be from a streak's axis, in pixels.
    #[arg(long, default_value_t = 12.0)]
    pub match_tolerance: f32,
}

/// Parses `name=x0,y0,x1,y1` ([`NamedRegion`]'s parser, with the name required: it names the
/// region's plot file).
pub fn parse_named_region(s: &str) -> Result<NamedRegion, String> {
    let region: NamedRegion = s.parse().map_err(|e: ImageError| e.to_string())?;
    if region.name.is_empty() {
        return Err(format!("expected name=x0,y0,x1,y1, got {s:?}"));
    }
    Ok(region)
}

impl Args {
    /// The analysis parameters these arguments select.
    pub fn params(&self) -> AnalyzeParams {
        let mut p = AnalyzeParams {
            lk: LkParams {
                window: self.window,
                rows: self.rows,
                ..LkParams::default()
            },
            regions: self.regions.clone(),
            auto_objects: self.objects,
            min_ncc: self.min_ncc,
            match_tolerance_px: self.match_tolerance,
            ..AnalyzeParams::default()
        };
        p.detect.horizon = self.horizon;
        p
    }
}

/// Runs the subcommand.
pub fn run(args: Args) -> Result<()> {
    crate::cli::analyze_pair(&args.dir, &args.params()).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;
    use streaks_image::Region;

    #[test]
    fn default_arguments_are_the_default_params() {
        // `streaks stereo --analyze` and `streaks paper` analyse with `AnalyzeParams::default()`:
        // the same as `streaks analyze DIR` with no flags.
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            args: Args,
        }
        let cli = <Cli as clap::Parser>::try_parse_from(["analyze", "dir"]).unwrap();
        assert_eq!(
            format!("{:?}", cli.args.params()),
            format!("{:?}", AnalyzeParams::default())
        );
    }

    #[test]
    fn named_regions_parse() {
        let r = parse_named_region("pole=10,20,25,200").unwrap();
        assert_eq!(r.name, "pole");
        assert_eq!(
            r.region,
            Region {
                x0: 10,
                y0: 20,
                x1: 25,
                y1: 200
            }
        );
        assert!(parse_named_region("10,20,25,200").is_err());
        assert!(parse_named_region("a b=1,2,3,4").is_err());
        assert!(parse_named_region("p=1,2,3").is_err());
    }
}
