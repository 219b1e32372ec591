//! The one door every user-supplied file comes in through: scenes and their
//! buffers and textures, budget profiles, stored frames and reports, the
//! images `compare` reads, fonts.
//!
//! Every read here is of a *regular* file (a FIFO would block the open until a
//! writer came, `/dev/zero` would never end), of at most a stated number of
//! bytes (the size is checked before anything is allocated, and the read
//! itself stops one byte past it, so a file that grows while it is read is
//! caught too). An image's decoded size is bounded *in the format dermis
//! converts it to* (RGBA8 for textures and frames, RGBA32F for EXRs) from its
//! header, before its pixels are allocated: a 100-byte PNG declaring
//! 100000 x 100000 pixels is refused, not decoded. Errors are one line naming
//! the file and what it was for (`what`: "scene file", "albedo texture",
//! "profile"...).
//!
//! Pure: no device, no graph. Writers are elsewhere (the output module).

use anyhow::{anyhow, bail, Result};
use std::fs::File;
use std::io::{Cursor, Read};
use std::path::Path;

/// Bytes in a mebibyte, for the bounds below.
pub const MIB: u64 = 1 << 20;

/// Largest scene file (glTF JSON or GLB) and largest external buffer: a GLB's
/// header counts its length in a u32, so 4 GiB is the format's own end; a dense
/// scan at dermis's vertex bound (`gltf_load::MAX_VERTICES`) is well under 2 GiB.
pub const MAX_SCENE_FILE: u64 = 2048 * MIB;
/// Largest image file (a skin texture is a few tens of MB at most).
pub const MAX_IMAGE_FILE: u64 = 1024 * MIB;
/// Largest text file dermis reads as data: profiles, stored frames, reports.
/// The longest report (100,000 measured frames keep statistics only) is a few
/// MB; a stored frame is tens of kB.
pub const MAX_TEXT_FILE: u64 = 64 * MIB;
/// Largest font file (DejaVu Sans is 750 kB; CJK fonts reach 20 MB).
pub const MAX_FONT_FILE: u64 = 64 * MIB;
/// Largest decoded image, in the format it is converted to: the `image` crate's
/// own default allocation limit, so an image refused here would have been
/// refused by the decoder too, only later and with a vaguer message (an RGBA8
/// texture of 8192 x 16384 fits; frames of dermis's largest side, 16384, at
/// RGBA8 would not, and do not fit the decoder either).
pub const MAX_DECODED_IMAGE: u64 = 512 * MIB;

/// The pixel format an image is converted to after decoding: what its decoded
/// size is counted in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pixels {
    /// 4 bytes a pixel (textures, PNG frames).
    Rgba8,
    /// 16 bytes a pixel (EXR captures: linear light, depth).
    Rgba32F,
}

impl Pixels {
    pub const fn bytes_per_pixel(self) -> u64 {
        match self {
            Pixels::Rgba8 => 4,
            Pixels::Rgba32F => 16,
        }
    }
}

/// What an image may be: its file's size, its sides and its decoded size in
/// `pixels`.
#[derive(Clone, Copy, Debug)]
pub struct ImageBound {
    pub max_file: u64,
    pub max_side: u32,
    pub max_decoded: u64,
    pub pixels: Pixels,
}

impl ImageBound {
    /// A texture or frame converted to RGBA8, of at most `max_side` pixels a side.
    pub const fn rgba8(max_side: u32) -> ImageBound {
        ImageBound {
            max_file: MAX_IMAGE_FILE,
            max_side,
            max_decoded: MAX_DECODED_IMAGE,
            pixels: Pixels::Rgba8,
        }
    }

    /// An EXR converted to RGBA32F, of at most `max_side` pixels a side.
    pub const fn rgba32f(max_side: u32) -> ImageBound {
        ImageBound {
            pixels: Pixels::Rgba32F,
            ..ImageBound::rgba8(max_side)
        }
    }

    /// Refuses a `width` x `height` image this bound does not allow.
    pub fn check(&self, width: u32, height: u32, what: &str) -> Result<()> {
        if width == 0 || height == 0 {
            bail!("{what} is empty ({width}x{height} pixels)");
        }
        if width > self.max_side || height > self.max_side {
            bail!(
                "{what} is {width}x{height} pixels, more than {} a side",
                self.max_side
            );
        }
        let bytes = width as u64 * height as u64 * self.pixels.bytes_per_pixel();
        if bytes > self.max_decoded {
            bail!(
                "{what} is {width}x{height} pixels: {} MiB decoded as {:?}, more than the {} MiB allowed",
                bytes.div_ceil(MIB),
                self.pixels,
                self.max_decoded / MIB
            );
        }
        Ok(())
    }
}

/// Opens `path` for reading if it is a regular file of at most `max_bytes`;
/// returns it and its size. The type is checked before the open (opening a FIFO
/// blocks) and again on the opened file (it may have been swapped in between).
pub fn open_regular(path: &Path, what: &str, max_bytes: u64) -> Result<(File, u64)> {
    let meta = std::fs::metadata(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => anyhow!("{what} not found: {}", path.display()),
        _ => anyhow!("cannot read {what} {}: {e}", path.display()),
    })?;
    if !meta.is_file() {
        bail!("{what} is not a regular file: {}", path.display());
    }
    let file =
        File::open(path).map_err(|e| anyhow!("cannot open {what} {}: {e}", path.display()))?;
    let meta = file
        .metadata()
        .map_err(|e| anyhow!("cannot read {what} {}: {e}", path.display()))?;
    if !meta.is_file() {
        bail!("{what} is not a regular file: {}", path.display());
    }
    if meta.len() > max_bytes {
        bail!(
            "{what} {} is {} bytes, more than the {max_bytes} allowed",
            path.display(),
            meta.len()
        );
    }
    Ok((file, meta.len()))
}

/// The whole of a regular file of at most `max_bytes`.
pub fn read_bounded(path: &Path, what: &str, max_bytes: u64) -> Result<Vec<u8>> {
    let (file, len) = open_regular(path, what, max_bytes)?;
    let mut data = Vec::with_capacity(len as usize);
    // One byte past the bound: a file that grew since its size was read is seen.
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut data)
        .map_err(|e| anyhow!("cannot read {what} {}: {e}", path.display()))?;
    if data.len() as u64 > max_bytes {
        bail!(
            "{what} {} grew past the {max_bytes} bytes allowed while it was read",
            path.display()
        );
    }
    Ok(data)
}

/// The first `len` bytes of a regular file that must hold at least that many
/// (a glTF buffer: the file's declared byteLength, whatever follows it unread).
pub fn read_prefix(path: &Path, what: &str, len: u64, max_bytes: u64) -> Result<Vec<u8>> {
    // The file may be longer than the bound: only `len` bytes of it are read.
    let (file, size) = open_regular(path, what, u64::MAX)?;
    if size < len {
        bail!(
            "{what} declares {len} bytes but {} has only {size}",
            path.display()
        );
    }
    if len > max_bytes {
        bail!(
            "{what} declares {len} bytes, more than the {max_bytes} allowed: {}",
            path.display()
        );
    }
    let mut data = Vec::with_capacity(len as usize);
    file.take(len)
        .read_to_end(&mut data)
        .map_err(|e| anyhow!("cannot read {what} {}: {e}", path.display()))?;
    if (data.len() as u64) < len {
        bail!(
            "{what} {} ended after {} of {len} bytes",
            path.display(),
            data.len()
        );
    }
    Ok(data)
}

/// A regular UTF-8 text file of at most `max_bytes`.
pub fn read_text(path: &Path, what: &str, max_bytes: u64) -> Result<String> {
    String::from_utf8(read_bounded(path, what, max_bytes)?)
        .map_err(|e| anyhow!("{what} {} is not UTF-8 text: {e}", path.display()))
}

/// Decodes image bytes (the format read from the bytes, not a name or MIME
/// type) after checking the header's size against `bound`. `what` names the
/// image in errors.
fn decode(bytes: &[u8], what: &str, bound: &ImageBound) -> Result<image::DynamicImage> {
    use image::ImageDecoder;
    let mut reader = image::ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| anyhow!("cannot decode {what}: {e}"))?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(bound.max_side);
    limits.max_image_height = Some(bound.max_side);
    reader.limits(limits);
    let decoder = match reader.into_decoder() {
        Ok(d) => d,
        // The decoder refused the header's size: say so in the bound's words.
        Err(image::ImageError::Limits(_)) => {
            let (w, h) = image::ImageReader::new(Cursor::new(bytes))
                .with_guessed_format()
                .ok()
                .and_then(|r| {
                    let mut r = r;
                    r.no_limits();
                    r.into_dimensions().ok()
                })
                .unwrap_or((u32::MAX, u32::MAX));
            bound.check(w, h, what)?;
            bail!("cannot decode {what}: its size exceeds the decoder's limits");
        }
        Err(e) => bail!("cannot decode {what}: {e}"),
    };
    let (w, h) = decoder.dimensions();
    bound.check(w, h, what)?;
    // The decoder's own buffer (its native format, up to 16 bytes a pixel) is
    // bounded by the same limit before it is allocated.
    if decoder.total_bytes() > bound.max_decoded {
        bail!(
            "{what} is {w}x{h} pixels: {} MiB to decode, more than the {} MiB allowed",
            decoder.total_bytes().div_ceil(MIB),
            bound.max_decoded / MIB
        );
    }
    image::DynamicImage::from_decoder(decoder).map_err(|e| anyhow!("cannot decode {what}: {e}"))
}

/// Image bytes (from a file already read, a glTF buffer view or a data: URI)
/// decoded to RGBA8, their size checked against `bound` first.
pub fn decode_rgba8(bytes: &[u8], what: &str, bound: &ImageBound) -> Result<image::RgbaImage> {
    Ok(decode(
        bytes,
        what,
        &ImageBound {
            pixels: Pixels::Rgba8,
            ..*bound
        },
    )?
    .to_rgba8())
}

/// An image file decoded to RGBA8 (textures, PNG frames).
pub fn read_rgba8(path: &Path, what: &str, bound: &ImageBound) -> Result<image::RgbaImage> {
    let bytes = read_bounded(path, what, bound.max_file)?;
    decode_rgba8(&bytes, &format!("{what} {}", path.display()), bound)
}

/// An image file decoded to RGBA32F (EXR captures).
pub fn read_rgba32f(path: &Path, what: &str, bound: &ImageBound) -> Result<image::Rgba32FImage> {
    let bytes = read_bounded(path, what, bound.max_file)?;
    let bound = ImageBound {
        pixels: Pixels::Rgba32F,
        ..*bound
    };
    Ok(decode(&bytes, &format!("{what} {}", path.display()), &bound)?.to_rgba32f())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> crate::scene::gltf_load::fixture::TempDir {
        crate::scene::gltf_load::fixture::temp_dir(&format!("files-{tag}"))
    }

    fn err<T>(r: Result<T>) -> String {
        match r {
            Ok(_) => panic!("expected an error"),
            Err(e) => format!("{e:#}"),
        }
    }

    /// A PNG whose header declares `w` x `h` RGBA8 pixels, with one IDAT chunk of a
    /// few bytes (the decoder reads up to it before it knows the size).
    pub(crate) fn png_header(w: u32, h: u32) -> Vec<u8> {
        let chunk = |v: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
            let mut c = kind.to_vec();
            c.extend(data);
            v.extend((data.len() as u32).to_be_bytes());
            v.extend(&c);
            v.extend(crc32(&c).to_be_bytes());
        };
        let mut ihdr = w.to_be_bytes().to_vec();
        ihdr.extend(h.to_be_bytes());
        ihdr.extend([8, 6, 0, 0, 0]);
        let mut v = b"\x89PNG\r\n\x1a\n".to_vec();
        chunk(&mut v, b"IHDR", &ihdr);
        chunk(
            &mut v,
            b"IDAT",
            &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
        );
        chunk(&mut v, b"IEND", &[]);
        v
    }

    fn crc32(b: &[u8]) -> u32 {
        let mut c = !0u32;
        for &x in b {
            c ^= x as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    #[test]
    fn only_regular_files_of_bounded_size_are_read() {
        let d = dir("regular");
        let f = d.join("a.txt");
        std::fs::write(&f, "hello").unwrap();
        assert_eq!(read_text(&f, "note", 5).unwrap(), "hello");
        let e = err(read_text(&f, "note", 4));
        assert!(e.contains("is 5 bytes, more than the 4 allowed"), "{e}");
        assert!(err(read_text(&d.join("none"), "note", 9)).contains("note not found"));
        assert!(err(read_bounded(&d, "note", 9)).contains("not a regular file"));
        // /dev/zero never ends: refused before it is opened.
        let e = err(read_bounded(Path::new("/dev/zero"), "profile", 9));
        assert!(
            e.contains("profile is not a regular file: /dev/zero"),
            "{e}"
        );
        std::fs::write(&f, [0xff, 0xfe]).unwrap();
        assert!(err(read_text(&f, "note", 9)).contains("not UTF-8"));
        std::fs::write(&f, [1, 2, 3, 4, 5]).unwrap();
        assert_eq!(read_prefix(&f, "buffer 0", 3, 9).unwrap(), [1, 2, 3]);
        let e = err(read_prefix(&f, "buffer 0", 9, 99));
        assert!(
            e.contains("declares 9 bytes but") && e.contains("has only 5"),
            "{e}"
        );
        assert!(err(read_prefix(&f, "buffer 0", 4, 3)).contains("more than the 3 allowed"));
        let _ = std::fs::remove_dir_all(d);
    }

    #[test]
    fn an_image_is_bounded_by_its_decoded_size_before_decoding() {
        let bomb = png_header(100_000, 100_000);
        assert!(bomb.len() < 80);
        let e = err(decode_rgba8(&bomb, "albedo", &ImageBound::rgba8(1 << 20)));
        assert!(e.contains("100000x100000 pixels"), "{e}");
        assert!(e.contains("more than the 512 MiB allowed"), "{e}");
        let e = err(decode_rgba8(&bomb, "albedo", &ImageBound::rgba8(16384)));
        assert!(e.contains("more than 16384 a side"), "{e}");
        // 8192 x 16384 RGBA8 is exactly the bound; RGBA32F is four times over.
        let b = ImageBound::rgba8(16384);
        b.check(8192, 16384, "t").unwrap();
        assert!(b.check(8193, 16384, "t").is_err());
        assert!(ImageBound::rgba32f(16384).check(8192, 16384, "t").is_err());
        // A real image decodes to the same pixels as the image crate's own reader.
        let img = image::RgbaImage::from_fn(3, 2, |x, y| image::Rgba([x as u8, y as u8, 7, 255]));
        let mut png = Cursor::new(Vec::new());
        img.write_to(&mut png, image::ImageFormat::Png).unwrap();
        let got = decode_rgba8(png.get_ref(), "t", &b).unwrap();
        assert_eq!(got, img);
        assert!(err(decode_rgba8(b"not an image", "t", &b)).contains("cannot decode t"));
    }
}
