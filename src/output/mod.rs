//! Every file dermis writes goes through one door, [`write_with`]: the bytes
//! go to a temporary file beside the final one (same folder, so the rename
//! cannot cross file systems), every error of the writes, of the final flush
//! and of `fsync` is returned, and only a complete file is renamed to its
//! final name. A failed run, a full disk or a killed process therefore never
//! leaves a truncated file under the name a reader looks for (at most a
//! hidden `.NAME.PID.tmp` beside it, from a killed run).
//!
//! Targets that are not regular files are handled by kind: a character
//! device (`/dev/null`, `/dev/full`, a terminal) is written in place, as a
//! rename over it would replace the device; anything else (a FIFO, a socket,
//! a block device, a folder) is refused with one line, before any work
//! (`check_writable_file`) and again at the write.
//!
//! The writers of each format dermis produces (PNG, EXR, JSON, text) and the
//! output-path checks made before any GPU work live here too, so `run` only
//! orchestrates.

pub mod paths;

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};

use crate::render::readback::DumpedImage;
use crate::render::Capture;

/// What an output path names today.
enum Target {
    /// Nothing, or a regular file: written under a temporary name and renamed.
    File,
    /// A character device: written in place.
    Device,
}

/// Classifies `path` (following a symbolic link to what it names); refuses
/// kinds a file cannot be written to.
fn target(path: &Path) -> Result<Target> {
    let meta = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Target::File),
        Err(e) => return Err(e).with_context(|| format!("checking {}", path.display())),
    };
    let t = meta.file_type();
    if t.is_file() {
        Ok(Target::File)
    } else if t.is_char_device() {
        Ok(Target::Device)
    } else if t.is_dir() {
        bail!(
            "{} is a directory, not a file dermis can write",
            path.display()
        )
    } else {
        let kind = if t.is_fifo() {
            "a FIFO"
        } else if t.is_socket() {
            "a socket"
        } else if t.is_block_device() {
            "a block device"
        } else {
            "not a regular file"
        };
        bail!(
            "{} is {kind}: dermis writes only regular files (or character devices such as /dev/null)",
            path.display()
        )
    }
}

/// The temporary name `path` is written under: hidden, beside it, unique to
/// this process.
fn temporary_name(path: &Path) -> Result<PathBuf> {
    let name = path
        .file_name()
        .with_context(|| format!("{} names no file", path.display()))?;
    let mut tmp = std::ffi::OsString::from(".");
    tmp.push(name);
    tmp.push(format!(".{}.tmp", std::process::id()));
    Ok(path.with_file_name(tmp))
}

/// Writes the file at `path` with `body`, through a buffered writer, making
/// its folder first (module docs: temporary name, every error surfaced,
/// renamed only when complete).
pub fn write_with(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> Result<()>,
) -> Result<()> {
    write_inner(path, body).with_context(|| format!("writing {}", path.display()))
}

fn write_inner(path: &Path, body: impl FnOnce(&mut BufWriter<File>) -> Result<()>) -> Result<()> {
    if let Target::Device = target(path)? {
        let file = OpenOptions::new().write(true).open(path)?;
        let mut w = BufWriter::new(file);
        body(&mut w)?;
        // `into_inner` flushes: a full device (/dev/full) fails here.
        w.into_inner().map_err(|e| e.into_error())?;
        return Ok(());
    }
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("creating {}", parent.display()))?;
    }
    let tmp = temporary_name(path)?;
    let written = (|| -> Result<()> {
        let file = OpenOptions::new()
            .write(true)
            .create(true)
            .truncate(true)
            .open(&tmp)
            .with_context(|| format!("creating {}", tmp.display()))?;
        let mut w = BufWriter::new(file);
        body(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        // Some file systems report a full disk only when the data reach it.
        file.sync_all()?;
        std::fs::rename(&tmp, path)
            .with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))
    })();
    if written.is_err() {
        // Nothing under the final name was touched; the partial file goes.
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// `bytes` as the file at `path` ([`write_with`]).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_with(path, |w| Ok(w.write_all(bytes)?))
}

/// `value` as pretty JSON at `path` ([`write_with`]).
pub fn write_json<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    write_with(path, |w| Ok(serde_json::to_writer_pretty(w, value)?))
}

/// An image encoded as `format` at `path` ([`write_with`]).
pub fn write_image(
    path: &Path,
    img: &image::DynamicImage,
    format: image::ImageFormat,
) -> Result<()> {
    // The encoders may seek (EXR's offset table): the buffered file can.
    write_with(path, |w| {
        img.write_to(w, format)
            .map_err(|e| encoding_error(e, format))
    })
}

/// An encoder's error as what it is: the image crate reports the EXR
/// encoder's failures (a full disk among them) as *decoding* errors, which
/// would send a user looking for a file dermis reads.
fn encoding_error(e: image::ImageError, format: image::ImageFormat) -> anyhow::Error {
    match e {
        image::ImageError::IoError(io) => {
            anyhow::Error::new(io).context(format!("encoding {format:?}"))
        }
        image::ImageError::Decoding(d) => {
            let cause =
                std::error::Error::source(&d).map_or_else(|| d.to_string(), |s| s.to_string());
            anyhow::anyhow!("encoding {format:?}: {cause}")
        }
        other => anyhow::anyhow!("encoding {format:?}: {other}"),
    }
}

/// An 8-bit RGBA picture (error images, bands) as PNG.
pub fn write_rgba8_png(path: &Path, width: u32, height: u32, rgba: Vec<u8>) -> Result<()> {
    let img = image::RgbaImage::from_raw(width, height, rgba)
        .with_context(|| format!("{}: the picture is not {width}x{height}", path.display()))?;
    write_image(
        path,
        &image::DynamicImage::ImageRgba8(img),
        image::ImageFormat::Png,
    )
}

/// `characters.png` of `render --character-ids`: 16-bit grey, each pixel its
/// character's frame index + 1 (0: no skin), row-major, top row first.
pub fn write_character_ids_png(path: &Path, width: u32, height: u32, ids: &[u32]) -> Result<()> {
    let px: Vec<u16> = ids.iter().map(|&i| i.min(u16::MAX as u32) as u16).collect();
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(width, height, px)
        .with_context(|| format!("{}: the picture is not {width}x{height}", path.display()))?;
    write_image(
        path,
        &image::DynamicImage::ImageLuma16(img),
        image::ImageFormat::Png,
    )
}

/// Reads `characters.png` back: each pixel's character + 1 (0: no skin).
pub fn read_character_ids_png(path: &Path) -> Result<(u32, u32, Vec<u32>)> {
    let bytes = crate::files::read_bounded(path, "character ids", crate::files::MAX_IMAGE_FILE)?;
    let reader =
        image::ImageReader::with_format(std::io::Cursor::new(&bytes), image::ImageFormat::Png);
    let (w, h) = reader
        .into_dimensions()
        .with_context(|| format!("decoding {}", path.display()))?;
    let side = crate::render::settings::MAX_IMAGE_SIDE;
    if w > side || h > side {
        bail!(
            "{}: {w}x{h} is larger than a frame ({side} a side)",
            path.display()
        );
    }
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
        .with_context(|| format!("decoding {}", path.display()))?
        .into_luma16();
    Ok((w, h, img.into_raw().into_iter().map(u32::from).collect()))
}

/// The sRGB tint of a method in `groups.png` (by its place in the registry).
pub fn method_tint(method: &str) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [66, 135, 245],  // separable: blue
        [60, 200, 90],   // ssg: green
        [245, 160, 40],  // ss-jittered: orange
        [170, 90, 230],  // poisson: purple
        [230, 60, 60],   // tsd: red
        [240, 110, 190], // tsd-opt: pink
        [255, 255, 255], // reference: white
        [128, 128, 128], // none: grey
    ];
    let i = crate::method::METHODS
        .iter()
        .position(|m| m.name == method)
        .unwrap_or(PALETTE.len() - 1);
    PALETTE[i % PALETTE.len()]
}

/// The tone-mapped frame `ldr` (RGBA8) with each character's skin pixels
/// (`ids`: character + 1, 0 no skin) mixed half and half with the tint of
/// its group (`tint_of[character]`): `groups.png`.
pub fn tint_characters(ldr: &[u8], ids: &[u32], tint_of: &[[u8; 3]]) -> Vec<u8> {
    let mut out = ldr.to_vec();
    for (px, &id) in out.chunks_exact_mut(4).zip(ids) {
        px[3] = 255;
        let Some(t) = (id as usize).checked_sub(1).and_then(|c| tint_of.get(c)) else {
            continue;
        };
        for k in 0..3 {
            px[k] = ((px[k] as u16 + t[k] as u16) / 2) as u8;
        }
    }
    out
}

/// Makes sure `dir` exists and can be written, before any GPU work: a bad
/// `--out` is reported at once, not after the render.
pub fn prepare_out_dir(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out {} exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let probe = dir.join(".dermis-write-test");
    std::fs::write(&probe, b"").with_context(|| format!("{} is not writable", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The files `run::render_to_dir` writes into its folder.
pub const RENDER_OUTPUTS: [&str; 4] = ["frame.png", "diffuse.exr", "depth.exr", "report.json"];

/// `prepare_out_dir`, and the files a render writes there (with `dump`, the
/// passes/ folder) can be written: each is checked before any GPU work, so a
/// bad `--out` never costs a render.
pub fn prepare_render_dir(dir: &Path, dump: bool) -> Result<()> {
    prepare_out_dir(dir)?;
    for name in RENDER_OUTPUTS {
        check_writable_file(&dir.join(name))?;
    }
    let passes = dir.join("passes");
    if dump && passes.exists() && !passes.is_dir() {
        bail!("--out: {} exists and is not a directory", passes.display());
    }
    Ok(())
}

/// A single output file (`bench --report`, `--trace`): its folder exists (or
/// is made) and is writable, and the path itself can be written. Checked
/// before any GPU work.
pub fn prepare_file(path: &Path) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !matches!(target(path), Ok(Target::Device)) {
            prepare_out_dir(parent)?;
        }
    }
    check_writable_file(path)
}

/// A file that is about to be (over)written: a kind [`write_with`] writes
/// (module docs), and writable if it exists (it is opened for appending,
/// which changes nothing).
pub fn check_writable_file(path: &Path) -> Result<()> {
    target(path)?;
    if path.exists() {
        OpenOptions::new()
            .append(true)
            .open(path)
            .with_context(|| format!("{} is not writable", path.display()))?;
    }
    Ok(())
}

/// Where the first non-finite (NaN or infinite) texel of `rgba` is, and how
/// many there are.
pub fn first_nonfinite(rgba: &[[f32; 4]], width: u32) -> Option<(usize, u32, u32)> {
    let count = rgba
        .iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count();
    let at = rgba.iter().position(|p| !p.iter().all(|c| c.is_finite()))?;
    let w = width.max(1) as usize;
    Some((count, (at % w) as u32, (at / w) as u32))
}

/// Writes the tone-mapped frame as an sRGB PNG. Refuses a frame whose HDR
/// composite held NaN or infinite values (they would be black pixels).
pub fn write_png(path: &Path, c: &Capture) -> Result<()> {
    if c.hdr_nonfinite > 0 {
        bail!(
            "not writing {}: {} pixel(s) of the frame before tone mapping are NaN or infinite (a renderer defect: please report it)",
            path.display(),
            c.hdr_nonfinite
        );
    }
    let mut rgba = c.ldr.clone();
    for px in rgba.chunks_exact_mut(4) {
        px[3] = 255;
    }
    write_rgba8_png(path, c.width, c.height, rgba)
}

/// Writes one pass output as a linear float EXR. Refuses an image holding NaN
/// or infinite values: no output of dermis ever does.
pub fn write_exr(path: &Path, d: &DumpedImage) -> Result<()> {
    if let Some((n, x, y)) = first_nonfinite(&d.rgba, d.width) {
        bail!(
            "not writing {}: {n} texel(s) of '{}' after '{}' are NaN or infinite, the first at ({x}, {y}) (a renderer defect: please report it)",
            path.display(),
            d.image,
            d.pass
        );
    }
    let data: Vec<f32> = d.rgba.iter().flatten().copied().collect();
    let img =
        image::Rgba32FImage::from_raw(d.width, d.height, data).context("dump size mismatch")?;
    write_image(
        path,
        &image::DynamicImage::ImageRgba32F(img),
        image::ImageFormat::OpenExr,
    )
}

/// Writes the diffuse light after SSS (linear, alpha = SSS strength) as EXR.
pub fn write_diffuse_exr(path: &Path, c: &Capture) -> Result<()> {
    write_exr(
        path,
        &DumpedImage {
            pass: "final".into(),
            image: "diffuse".into(),
            width: c.width,
            height: c.height,
            rgba: c.diffuse.clone(),
        },
    )
}

/// Writes the linear view depth (scene units, in R, G and B) as EXR: with
/// report.json's fovy_deg and mm_per_unit, what `compare` finds the accuracy
/// bands from.
pub fn write_depth_exr(path: &Path, c: &Capture) -> Result<()> {
    write_exr(
        path,
        &DumpedImage {
            pass: "final".into(),
            image: "linear depth".into(),
            width: c.width,
            height: c.height,
            rgba: c.depth.iter().map(|&d| [d, d, d, 1.0]).collect(),
        },
    )
}

/// Reads an RGBA EXR written by dermis (what `compare` reads back of the
/// writers above).
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    // Its sides within the range `render` accepts for a frame's width and height.
    let img = crate::files::read_rgba32f(
        path,
        "EXR image",
        &crate::files::ImageBound::rgba32f(crate::render::settings::MAX_IMAGE_SIDE),
    )?;
    let (w, h) = img.dimensions();
    Ok((w, h, img.pixels().map(|p| p.0).collect()))
}

/// A file-name-safe version of a pass or image name.
pub fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect::<String>()
        .split('_')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> crate::scene::gltf_load::fixture::TempDir {
        crate::scene::gltf_load::fixture::temp_dir(&format!("output-{name}"))
    }

    /// The names in `d`, sorted.
    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    // Issue 11: NaN texture coordinates gave NaN pixels in diffuse.exr. The
    // writers refuse non-finite images with a clear error, and write nothing.
    #[test]
    fn writers_refuse_nan_and_inf() {
        let d = tmp("nan");
        let mut img = DumpedImage {
            pass: "final".into(),
            image: "diffuse".into(),
            width: 3,
            height: 2,
            rgba: vec![[0.5; 4]; 6],
        };
        write_exr(&d.join("ok.exr"), &img).unwrap();
        let (w, h, back) = read_exr(&d.join("ok.exr")).unwrap();
        assert_eq!((w, h), (3, 2));
        assert_eq!(back, img.rgba);
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            img.rgba[4][1] = bad;
            let p = d.join("bad.exr");
            let e = write_exr(&p, &img).unwrap_err().to_string();
            assert!(e.contains("1 texel(s)") && e.contains("(1, 1)"), "{e}");
            assert!(!p.exists());
        }
        let mut c = Capture {
            ldr: vec![0; 6 * 4],
            width: 3,
            height: 2,
            dumps: Vec::new(),
            samples: Vec::new(),
            diffuse: vec![[0.0; 4]; 6],
            depth: vec![1.0; 6],
            hdr_nonfinite: 0,
            character_ids: None,
        };
        write_png(&d.join("ok.png"), &c).unwrap();
        c.hdr_nonfinite = 2;
        let e = write_png(&d.join("bad.png"), &c).unwrap_err().to_string();
        assert!(e.contains("2 pixel(s)"), "{e}");
        assert!(!d.join("bad.png").exists());
        assert_eq!(names(&d), ["ok.exr", "ok.png"]);
        let _ = std::fs::remove_dir_all(d);
    }

    // Issue 15 item 11: a body that fails half way leaves the old file whole
    // under its name and no temporary beside it.
    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_temporary() {
        let d = tmp("atomic");
        let p = d.join("report.json");
        write_bytes(&p, b"old and complete").unwrap();
        let e = write_with(&p, |w| {
            w.write_all(b"half of the new")?;
            w.flush()?;
            bail!("the disk went away")
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains("writing") && format!("{e:#}").contains("went away"));
        assert_eq!(std::fs::read(&p).unwrap(), b"old and complete");
        assert_eq!(names(&d), ["report.json"]);
        write_json(&p, &[1, 2]).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "[\n  1,\n  2\n]");
        assert_eq!(names(&d), ["report.json"]);
        let _ = std::fs::remove_dir_all(d);
    }

    // /dev/full fails every write with ENOSPC: the error reaches the caller
    // (the buffered bytes fail at the flush) and the device is not replaced.
    #[test]
    fn a_full_device_is_an_error() {
        let full = Path::new("/dev/full");
        if !full.exists() {
            return;
        }
        let e = write_bytes(full, b"{}").unwrap_err();
        let msg = format!("{e:#}");
        assert!(msg.contains("/dev/full") && msg.contains("space"), "{msg}");
        assert!(std::fs::metadata(full)
            .unwrap()
            .file_type()
            .is_char_device());
        write_bytes(Path::new("/dev/null"), b"fine").unwrap();
    }

    #[test]
    fn fifos_and_folders_are_refused_before_any_work() {
        let d = tmp("kinds");
        let fifo = d.join("fifo.json");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = check_writable_file(&fifo).unwrap_err().to_string();
            assert!(e.contains("is a FIFO"), "{e}");
            let e = format!("{:#}", write_bytes(&fifo, b"x").unwrap_err());
            assert!(e.contains("is a FIFO"), "{e}");
        }
        let e = prepare_file(&d).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        prepare_file(Path::new("/dev/null")).unwrap();
        let _ = std::fs::remove_dir_all(d);
    }

    // Issue 11: `--out` problems were found only after the render.
    #[test]
    fn output_paths_are_checked_before_any_work() {
        let d = tmp("out");
        let file = d.join("a-file");
        std::fs::write(&file, b"x").unwrap();
        let e = prepare_render_dir(&file, false).unwrap_err().to_string();
        assert!(e.contains("not a directory"), "{e}");
        let e = prepare_render_dir(&file.join("below"), false).unwrap_err();
        assert!(format!("{e:#}").contains("creating"), "{e:#}");
        // An output name taken by a folder.
        let out = d.join("out");
        std::fs::create_dir_all(out.join("frame.png")).unwrap();
        let e = prepare_render_dir(&out, false).unwrap_err().to_string();
        assert!(e.contains("frame.png is a directory"), "{e}");
        prepare_render_dir(&d.join("fresh"), true).unwrap();
        // bench --report: a folder, or below a file.
        let e = prepare_file(&out).unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        assert!(prepare_file(&file.join("r.json")).is_err());
        prepare_file(&d.join("new/r.json")).unwrap();
        let _ = std::fs::remove_dir_all(d);
    }

    #[test]
    fn slugs_are_file_safe() {
        assert_eq!(slug("sss horizontal -> diffuse"), "sss_horizontal_diffuse");
        assert_eq!(slug("Shadow Map"), "shadow_map");
    }

    // characters.png round-trips 16-bit ids (past 255 characters), and the
    // tint mixes skin pixels only.
    #[test]
    fn character_ids_round_trip_and_tint_skin_only() {
        let d = crate::scene::gltf_load::fixture::temp_dir("ids");
        let ids = vec![0, 1, 256, 1024, 2, 0];
        let p = d.join("characters.png");
        write_character_ids_png(&p, 3, 2, &ids).unwrap();
        let (w, h, back) = read_character_ids_png(&p).unwrap();
        assert_eq!((w, h), (3, 2));
        assert_eq!(back, ids);
        let ldr = vec![100u8; 6 * 4];
        let tint = [[200, 0, 100]; 1024];
        let out = tint_characters(&ldr, &ids, &tint);
        assert_eq!(&out[0..4], &[100, 100, 100, 255]);
        assert_eq!(&out[4..8], &[150, 50, 100, 255]);
        assert_eq!(method_tint("separable"), [66, 135, 245]);
        assert_ne!(method_tint("ssg"), method_tint("none"));
        let _ = std::fs::remove_dir_all(d);
    }
}
