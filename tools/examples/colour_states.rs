//! The built-in face's colour states (thesis ch. 7) as maps over the face's
//! part of its UV square, one column a state (neutral, then `STATES`' order:
//! joy, surprise, fear, anger, disgust, sad, exercise, alcohol, blush):
//! - row 1: the dermal haemoglobin the appearance rig gives (eq. 7.6), 0% black to 4% white;
//! - row 2: the skin's albedo through the colour table (eq. 7.7) at 1% melanin;
//! - row 3: the same at the light tone's melanin (3.8%: `--skin-tone light`),
//!   where the epidermis hides much of the blood's hue.
//!
//! ```sh
//! cargo run --release --features tools --example colour_states -- OUT.jpg (or OUT.png)
//! ```

use anyhow::{bail, Context, Result};
use dermis::scene::face_colour::{COLOUR_SIZE, STATES};
use dermis::skin::colour::colorimetry::srgb8;
use dermis::skin::colour::face::FaceAppearance;
use dermis::skin::colour::lut::{tone_melanin, ColourTable};

/// The face's rows and columns of the maps: azimuths within 60 degrees of
/// the face's front, heights from the hairline to under the chin.
const ROWS: (usize, usize) = (112, 276);
const COLS: (usize, usize) = (170, 342);

/// A linear value (or colour) to 8-bit sRGB.
fn srgb(c: [f32; 3]) -> [u8; 3] {
    srgb8(c.map(f64::from))
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [out] = args.as_slice() else {
        bail!("usage: colour_states OUT.jpg");
    };
    let table = ColourTable::new(64);
    let faces = [
        FaceAppearance::builtin(0.01),
        FaceAppearance::builtin(tone_melanin(dermis::scene::source::SkinTone::Light) as f32),
    ];
    let columns: Vec<Vec<f32>> = std::iter::once(vec![0.0; STATES.len()])
        .chain((0..STATES.len()).map(|k| (0..STATES.len()).map(|i| f32::from(i == k)).collect()))
        .collect();
    let (w, h) = (COLS.1 - COLS.0, ROWS.1 - ROWS.0);
    let mut sheet = image::RgbImage::new((w * columns.len()) as u32, (h * 3) as u32);
    for (c, weights) in columns.iter().enumerate() {
        let blood = faces[0].rig.haemoglobin(weights);
        let albedo = faces
            .iter()
            .map(|f| f.albedo(weights, &table))
            .collect::<Vec<_>>();
        for y in 0..h {
            for x in 0..w {
                let k = (y + ROWS.0) * COLOUR_SIZE + x + COLS.0;
                let px = |row: usize| ((c * w + x) as u32, (row * h + y) as u32);
                let g = blood.data[k] / 0.04;
                sheet.put_pixel(px(0).0, px(0).1, image::Rgb(srgb([g; 3])));
                for (r, a) in albedo.iter().enumerate() {
                    let (x1, y1) = px(r + 1);
                    sheet.put_pixel(x1, y1, image::Rgb(srgb(a[k])));
                }
            }
        }
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
    println!("wrote {out}: {} states x 3 rows of {w}x{h}", columns.len());
    Ok(())
}
