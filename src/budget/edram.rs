//! eDRAM arithmetic (Xbox 360): how many tiles a pass's render targets take,
//! whether they fit or the pass needs predicated tiling, and what a resolve moves.

use crate::budget::profile::Edram;

/// Samples across and down of a `width` x `height` surface at `msaa` samples:
/// 2x MSAA doubles the height, 4x doubles both (HARDWARE.md, xenos.h).
pub fn sample_dims(width: u32, height: u32, msaa: u32) -> (u32, u32) {
    let ws = if msaa >= 4 { width * 2 } else { width };
    let hs = if msaa >= 2 { height * 2 } else { height };
    (ws, hs)
}

/// Tiles of one band of tile rows (`tile_height_samples` high) of a surface of
/// `bytes` per sample: a 64 bpp format takes twice the tiles of a 32 bpp one.
fn tiles_per_row(ws: u32, bytes: u32, e: &Edram) -> u32 {
    ws.div_ceil(e.tile_width_samples) * bytes.div_ceil(4)
}

/// Tiles a whole surface takes.
pub fn surface_tiles(width: u32, height: u32, msaa: u32, bytes: u32, e: &Edram) -> u32 {
    let (ws, hs) = sample_dims(width, height, msaa);
    tiles_per_row(ws, bytes, e) * hs.div_ceil(e.tile_height_samples)
}

/// Screen tiles (predicated-tiling passes) needed for targets of `bytes` per
/// sample each (colour and depth together): the screen is cut into bands of
/// whole tile rows, each band's targets fitting in `e.tiles`. `None` when not
/// even one row of tiles fits.
pub fn screen_tiles(width: u32, height: u32, msaa: u32, bytes: &[u32], e: &Edram) -> Option<u32> {
    let (ws, hs) = sample_dims(width, height, msaa);
    let per_row: u32 = bytes.iter().map(|&b| tiles_per_row(ws, b, e)).sum();
    if per_row == 0 {
        return Some(1);
    }
    let rows_per_band = e.tiles / per_row;
    if rows_per_band == 0 {
        return None;
    }
    Some(hs.div_ceil(e.tile_height_samples).div_ceil(rows_per_band))
}

/// Bytes a resolve of a `width` x `height` target writes to main memory: one
/// value per pixel (MSAA samples are averaged on the way out).
pub fn resolve_bytes(width: u32, height: u32, bytes_per_pixel: u32) -> u64 {
    u64::from(width) * u64::from(height) * u64::from(bytes_per_pixel)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::budget::profile::Quantity;

    fn xenos() -> Edram {
        Edram {
            size_mib: 10.0,
            tiles: 2048,
            tile_width_samples: 80,
            tile_height_samples: 16,
            tile_bytes: 5120,
            internal_gbps: Quantity::Known(256.0),
            link_gbps: Quantity::Known(32.0),
            resolve_gbps: Quantity::Known(22.4),
            tiled_geometry_factor: Quantity::Known(1.25),
        }
    }

    #[test]
    fn tile_counts_of_hardware_md() {
        let e = xenos();
        let st = |msaa, b: &[u32]| screen_tiles(1280, 720, msaa, b, &e).unwrap();
        // 32 bpp colour + D24S8: 1 (1x), 2 (2x), 3 (4x).
        assert_eq!(st(1, &[4, 4]), 1);
        assert_eq!(st(2, &[4, 4]), 2);
        assert_eq!(st(4, &[4, 4]), 3);
        // FP16 colour + depth: 2 (1x), 3 (2x), 5 (4x).
        assert_eq!(st(1, &[8, 4]), 2);
        assert_eq!(st(2, &[8, 4]), 3);
        assert_eq!(st(4, &[8, 4]), 5);
        // Three 32 bpp MRTs + depth at 1x: 2.
        assert_eq!(st(1, &[4, 4, 4, 4]), 2);
    }

    #[test]
    fn surface_footprints() {
        let e = xenos();
        // 1280x720 at 32 bpp: 16 x 45 tiles; the tiles hold exactly its bytes.
        assert_eq!(surface_tiles(1280, 720, 1, 4, &e), 720);
        assert_eq!(
            u64::from(surface_tiles(1280, 720, 1, 4, &e)) * 5120,
            resolve_bytes(1280, 720, 4)
        );
        assert_eq!(surface_tiles(1280, 720, 1, 8, &e), 1440);
        assert_eq!(surface_tiles(1280, 720, 4, 8, &e), 5760);
        // 10 MiB is 2048 tiles of 5120 bytes.
        assert_eq!(2048 * 5120, 10 * 1024 * 1024);
    }

    #[test]
    fn resolve_bytes_of_known_targets() {
        // HARDWARE.md: 720p at 32 bpp is 3.69 MB, at 64 bpp 7.37 MB.
        assert_eq!(resolve_bytes(1280, 720, 4), 3_686_400);
        assert_eq!(resolve_bytes(1280, 720, 8), 7_372_800);
        // 1080p RGBA16F: 16.6 MB.
        assert_eq!(resolve_bytes(1920, 1080, 8), 16_588_800);
    }
}
