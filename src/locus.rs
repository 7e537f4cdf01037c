//! `streaks locus`: the locus of the virtual light `L_virtual` (Eq. 4) for ground points
//! between a viewer and a point light (the `h_X = 0` family of the paper's proof), with the
//! angular disparity a stereo rig at the viewer sees, as CSV or JSON on standard output; or,
//! with `--model centre`, the streak-centre model at the same ground depths (each eye's
//! brightest point of the row and their disparity, beside Eq. 4's).

use anyhow::{Context, Result};
use glam::DVec3;
use serde::Serialize;
use std::io::Write;
use streaks_analysis::centre::CentreModel;
use streaks_analysis::model::ColumnModel;
use streaks_stereo::rig::RoadRig;

/// Which model to print.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// Eq. 4's virtual lights (the `h_X = 0` family).
    Eq4,
    /// The streak-centre model: the brightest point of each row in each eye.
    Centre,
}

/// Output format.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Comma-separated values with a header line.
    Csv,
    /// A JSON array of objects.
    Json,
}

/// Print the virtual light column of a point light seen from a viewer (road frame: metres,
/// Y up, road at Y = 0, Z forward, X right).
#[derive(clap::Args, Debug)]
pub struct Args {
    /// The light's position X,Y,Z (above the road, ahead of the viewer).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub light: DVec3,
    /// The viewer's (stereo rig centre's) position X,Y,Z.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub viewer: DVec3,
    /// Keep only ground points whose half vector h is within this many degrees of vertical
    /// (the paper's Fig. 4 uses 4).
    #[arg(long, value_name = "DEG")]
    pub max_tilt: Option<f64>,
    /// Number of ground depths, equally spaced over the kept range (ends included).
    #[arg(long, default_value_t = 50)]
    pub samples: usize,
    /// Stereo baseline in metres (eyes at the viewer -/+ B/2 along X, looking along +Z).
    #[arg(long, default_value_t = 0.065, value_name = "B")]
    pub baseline: f64,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// The model: `eq4` (columns ground_x, ground_z, virtual_x/y/z, tilt_deg, elevation_deg,
    /// disparity_deg) or `centre` (ground_z, left_x, right_x, tilt_deg, elevation_deg,
    /// disparity_deg, plane_offset, eq4_disparity_deg).
    #[arg(long, value_enum, default_value_t = Model::Eq4)]
    pub model: Model,
}

/// Parses "X,Y,Z" into a point.
fn parse_point(s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected X,Y,Z (three comma-separated numbers), got '{s}'"
        ));
    };
    let num = |t: &str| {
        t.parse::<f64>()
            .map_err(|_| format!("'{t}' in '{s}' is not a number"))
    };
    Ok(DVec3::new(num(x)?, num(y)?, num(z)?))
}

/// One output line.
#[derive(Serialize, Debug)]
struct Row {
    /// Ground point X (the `h_X = 0` point of its depth; the light's X if the viewer shares it).
    ground_x: f64,
    /// Ground depth Z.
    ground_z: f64,
    virtual_x: f64,
    virtual_y: f64,
    virtual_z: f64,
    /// Angle of h from vertical.
    tilt_deg: f64,
    /// Elevation angle below the horizon of the ground point seen from the viewer.
    elevation_deg: f64,
    /// Angular disparity of L_virtual: left-eye minus right-eye horizontal visual angle.
    disparity_deg: f64,
}

/// One output line of `--model centre`.
#[derive(Serialize, Debug)]
struct CentreLine {
    /// Ground depth Z of the row.
    ground_z: f64,
    /// The left eye's brightest point of the row, X.
    left_x: f64,
    /// The right eye's, X.
    right_x: f64,
    /// Angle of the left peak's h from vertical.
    tilt_deg: f64,
    /// Elevation below the horizon of the left peak seen from the viewer.
    elevation_deg: f64,
    /// Angular disparity of the streak centre (left azimuth of the left peak minus right
    /// azimuth of the right peak).
    disparity_deg: f64,
    /// Distance of the left peak from the plane through the left eye and the light's
    /// vertical line, metres.
    plane_offset: f64,
    /// Eq. 4's angular disparity at the same depth.
    eq4_disparity_deg: f64,
}

/// Writes `rows` as JSON or as CSV with `header` and `fields` per row.
fn write_rows<T: Serialize>(
    format: Format,
    rows: &[T],
    header: &str,
    fields: impl Fn(&T) -> Vec<f64>,
) -> Result<()> {
    let mut out = std::io::stdout().lock();
    match format {
        Format::Json => {
            serde_json::to_writer_pretty(&mut out, rows).context("writing JSON")?;
            writeln!(out)?;
        }
        Format::Csv => {
            writeln!(out, "{header}")?;
            for r in rows {
                let line: Vec<String> = fields(r).iter().map(f64::to_string).collect();
                writeln!(out, "{}", line.join(","))?;
            }
        }
    }
    out.flush().context("writing standard output")?;
    Ok(())
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let model = ColumnModel::new(args.light, args.viewer).context("invalid --light/--viewer")?;
    if args.model == Model::Centre {
        let rig = RoadRig::level(args.viewer, 1.0, args.baseline).context("invalid --baseline")?;
        let centre = CentreModel::new(args.light, rig).context("invalid --light/--viewer")?;
        let rows: Vec<CentreLine> = centre
            .rows(args.max_tilt, args.samples)
            .context("cannot compute the streak-centre model")?
            .into_iter()
            .map(|r| CentreLine {
                ground_z: r.ground_z,
                left_x: r.left_x,
                right_x: r.right_x,
                tilt_deg: r.tilt_deg,
                elevation_deg: r.elevation_deg,
                disparity_deg: r.disparity_deg,
                plane_offset: r.plane_offset,
                eq4_disparity_deg: r.eq4_disparity_deg,
            })
            .collect();
        return write_rows(
            args.format,
            &rows,
            "ground_z,left_x,right_x,tilt_deg,elevation_deg,disparity_deg,plane_offset,eq4_disparity_deg",
            |r| {
                vec![
                    r.ground_z,
                    r.left_x,
                    r.right_x,
                    r.tilt_deg,
                    r.elevation_deg,
                    r.disparity_deg,
                    r.plane_offset,
                    r.eq4_disparity_deg,
                ]
            },
        );
    }
    let points = model
        .locus_profile(args.max_tilt, args.samples, args.baseline)
        .context("cannot compute the locus")?;
    let rows: Vec<Row> = points
        .iter()
        .map(|p| {
            let r = &p.reflection;
            Row {
                ground_x: r.ground.x,
                ground_z: r.ground.z,
                virtual_x: r.virtual_light.x,
                virtual_y: r.virtual_light.y,
                virtual_z: r.virtual_light.z,
                tilt_deg: r.tilt_deg,
                elevation_deg: p.elevation_deg,
                disparity_deg: p.disparity_deg,
            }
        })
        .collect();
    write_rows(
        args.format,
        &rows,
        "ground_x,ground_z,virtual_x,virtual_y,virtual_z,tilt_deg,elevation_deg,disparity_deg",
        |r| {
            vec![
                r.ground_x,
                r.ground_z,
                r.virtual_x,
                r.virtual_y,
                r.virtual_z,
                r.tilt_deg,
                r.elevation_deg,
                r.disparity_deg,
            ]
        },
    )
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

    fn parse(extra: &[&str]) -> Result<Args, clap::Error> {
        let mut argv = vec!["locus"];
        argv.extend_from_slice(extra);
        Cli::try_parse_from(argv).map(|c| c.args)
    }

    #[test]
    fn parses_points_and_options() {
        let a = parse(&[
            "--light",
            "0,1.5,15",
            "--viewer",
            "-0.5, 1.5, 0",
            "--max-tilt",
            "4",
            "--samples",
            "7",
            "--format",
            "json",
        ])
        .unwrap();
        assert_eq!(a.light, DVec3::new(0.0, 1.5, 15.0));
        assert_eq!(a.viewer, DVec3::new(-0.5, 1.5, 0.0));
        assert_eq!(
            (a.max_tilt, a.samples, a.baseline, a.format),
            (Some(4.0), 7, 0.065, Format::Json)
        );
    }

    #[test]
    fn malformed_arguments_are_parse_errors() {
        for bad in [
            &["--light", "0,1.5", "--viewer", "0,1.5,0"][..],
            &["--light", "0,1.5,15,2", "--viewer", "0,1.5,0"],
            &["--light", "0,x,15", "--viewer", "0,1.5,0"],
            &["--light", "0,1.5,15"],
            &[
                "--light",
                "0,1.5,15",
                "--viewer",
                "0,1.5,0",
                "--samples",
                "-1",
            ],
            &[
                "--light", "0,1.5,15", "--viewer", "0,1.5,0", "--format", "xml",
            ],
        ] {
            assert!(parse(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn bad_values_are_errors_not_panics() {
        for bad in [
            &["--light", "0,nan,15", "--viewer", "0,1.5,0"][..],
            &["--light", "0,-1,15", "--viewer", "0,1.5,0"],
            &["--light", "0,1.5,0", "--viewer", "0,1.5,0"],
            &[
                "--light",
                "0,1.5,15",
                "--viewer",
                "0,1.5,0",
                "--samples",
                "0",
            ],
            &[
                "--light",
                "0,1.5,15",
                "--viewer",
                "0,1.5,0",
                "--max-tilt",
                "95",
            ],
            &[
                "--light",
                "0,1.5,15",
                "--viewer",
                "0,1.5,0",
                "--baseline",
                "0",
            ],
        ] {
            let err = run(parse(bad).unwrap()).unwrap_err();
            assert!(!format!("{err:#}").is_empty());
        }
        let centre = parse(&[
            "--light", "0,-1,15", "--viewer", "0,1.5,0", "--model", "centre",
        ]);
        assert!(run(centre.unwrap()).is_err());
        let err = run(parse(&["--light", "0,1.5,0", "--viewer", "0,1.5,0"]).unwrap()).unwrap_err();
        assert!(format!("{err:#}").contains("light's depth"), "{err:#}");
    }
}
