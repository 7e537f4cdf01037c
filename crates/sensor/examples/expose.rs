//! Exposes a render's EXR through a camera profile and writes the developed PNG, to try
//! profiles without rendering again:
//! `cargo run -p streaks-sensor --example expose -- RENDER.exr PRESET|FILE.toml FOCAL_PX EV SEED OUT.png`.

use std::path::Path;
use streaks_image::exr::read_exr_rgb;
use streaks_image::png::write_png_buffer;
use streaks_sensor::{capture, SensorProfile};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [exr, profile, focal, ev, seed, out] = args.as_slice() else {
        return Err("usage: expose RENDER.exr PRESET|FILE.toml FOCAL_PX EV SEED OUT.png".into());
    };
    let image = read_exr_rgb(Path::new(exr))?;
    let profile = SensorProfile::resolve(profile)?;
    let start = std::time::Instant::now();
    let raw = capture(&profile, &image, focal.parse()?, ev.parse()?, seed.parse()?)?;
    eprintln!("exposed in {:.3} s", start.elapsed().as_secs_f64());
    let mut lum: Vec<f32> = image.pixels.iter().map(|p| p.y).collect();
    lum.sort_by(f32::total_cmp);
    let q = |f: f64| lum[((lum.len() - 1) as f64 * f) as usize];
    let white = profile.white_dn() as f32;
    let saturated = raw.dn.pixels.iter().filter(|p| p.y >= white - 1.0).count();
    let mut g: Vec<f32> = raw.dn.pixels.iter().map(|p| p.y).collect();
    g.sort_by(f32::total_cmp);
    eprintln!(
        "radiance G: median {:.4}, 99 % {:.4}, 99.9 % {:.3}, max {:.1}; DN G: 1 % {}, median {}, 99 % {}; {saturated} pixels at white",
        q(0.5), q(0.99), q(0.999), q(1.0), g[g.len() / 100], g[g.len() / 2], g[g.len() * 99 / 100]
    );
    let mut png = raw.develop();
    // CROP=x,y,w,h,zoom: write only that part, each pixel zoom x zoom (to look at halos).
    if let Ok(crop) = std::env::var("CROP") {
        let v: Vec<u32> = crop.split(',').map(str::parse).collect::<Result<_, _>>()?;
        let [x, y, w, h, zoom] = v[..] else {
            return Err("CROP=x,y,w,h,zoom".into());
        };
        let part = image::imageops::crop_imm(&png, x, y, w, h).to_image();
        png = image::imageops::resize(&part, w * zoom, h * zoom, image::imageops::Nearest);
    }
    write_png_buffer(Path::new(out), &png)?;
    Ok(())
}
