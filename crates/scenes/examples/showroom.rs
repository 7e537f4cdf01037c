//! Writes the objects' showrooms (`showroom_night.gltf`, `showroom_day.gltf`) into a
//! directory: `cargo run -p streaks-scenes --example showroom -- DIR`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args().nth(1).ok_or("usage: showroom DIR")?;
    let dir = std::path::Path::new(&dir);
    std::fs::create_dir_all(dir)?;
    for night in [true, false] {
        for p in streaks_scenes::objects::showroom::showroom(night)?.write(dir)? {
            println!("{}", p.display());
        }
    }
    Ok(())
}
