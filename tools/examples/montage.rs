//! Lays images out in a grid, row by row, into one JPEG (quality 88), or a
//! PNG when OUT ends in `.png` (the docs' pictures: `tools/pictures_issue30.sh`).
//! Every image must have the first one's size.
//!
//! ```sh
//! cargo run --release --features tools --example montage -- OUT.jpg COLUMNS A.png B.png ...
//! ```

use anyhow::{bail, Context, Result};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out, cols, images @ ..] = args.as_slice() else {
        bail!("usage: montage OUT.jpg COLUMNS IMAGE...");
    };
    let cols: u32 = cols.parse().context("COLUMNS: a whole number")?;
    if cols == 0 || images.is_empty() {
        bail!("montage needs at least one column and one image");
    }
    let tiles = images
        .iter()
        .map(|p| {
            Ok(image::open(p)
                .with_context(|| format!("reading {p}"))?
                .to_rgb8())
        })
        .collect::<Result<Vec<_>>>()?;
    let (w, h) = tiles[0].dimensions();
    if let Some(p) = images
        .iter()
        .zip(&tiles)
        .find(|(_, t)| t.dimensions() != (w, h))
    {
        bail!("{} is not {w}x{h}, the first image's size", p.0);
    }
    let rows = (tiles.len() as u32).div_ceil(cols);
    let mut sheet = image::RgbImage::new(w * cols, h * rows);
    for (k, t) in tiles.iter().enumerate() {
        let (c, r) = (k as u32 % cols, k as u32 / cols);
        image::imageops::replace(&mut sheet, t, (c * w) as i64, (r * h) as i64);
    }
    if out.ends_with(".png") {
        sheet.save(out).with_context(|| format!("writing {out}"))?;
    } else {
        let file = std::fs::File::create(out).with_context(|| format!("creating {out}"))?;
        let mut enc =
            image::codecs::jpeg::JpegEncoder::new_with_quality(std::io::BufWriter::new(file), 88);
        enc.encode_image(&sheet)
            .with_context(|| format!("writing {out}"))?;
    }
    println!("wrote {out}: {} x {} tiles of {w}x{h}", cols, rows);
    Ok(())
}
