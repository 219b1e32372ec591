// The tests of smaa_area.rs (a file of their own to keep both short).
use super::*;
use crate::aa::edges::{smaa_luma_edges, Channel, Image, LocalContrast, Preset};

fn p(i: usize) -> Pattern {
    Pattern::from_index(i)
}

/// The areas of an orthogonal pattern at tile texel (x, y), offset index k.
fn ortho(t: &SmaaAreaTex, i: usize, x: usize, y: usize, k: usize) -> [f32; 2] {
    let (cx, cy) = ortho_texel(p(i), x, y, k);
    t.at(cx, cy)
}

fn near(a: [f32; 2], b: [f64; 2]) -> bool {
    (f64::from(a[0]) - b[0]).abs() < 1e-6 && (f64::from(a[1]) - b[1]).abs() < 1e-6
}

#[test]
fn sizes_are_the_standard_ones() {
    let t = area_tex();
    assert_eq!((WIDTH, HEIGHT), (160, 560));
    assert_eq!(t.texels.len(), WIDTH * HEIGHT);
    assert_eq!(area_tex_rg8().len(), 2 * WIDTH * HEIGHT);
    assert_eq!(5 * ORTHO_TILE, WIDTH / 2);
    assert_eq!(4 * DIAG_TILE, SUBTEX_ROWS);
}

#[test]
fn the_cache_generates_once_and_the_bytes_match() {
    assert!(std::ptr::eq(area_tex(), area_tex()));
    assert_eq!(area_tex_rg8(), &area_tex().rg8()[..]);
    assert_eq!(&SmaaAreaTex::generate(), area_tex());
}

#[test]
fn texcoords_land_on_the_texel_centres() {
    for k in 0..ORTHO_OFFSETS.len() {
        for i in 0..16 {
            for y in 0..ORTHO_TILE {
                for x in 0..ORTHO_TILE {
                    let pat = p(i);
                    let tc = ortho_texcoord(
                        [x as f32, y as f32],
                        pat.left.fetched(),
                        pat.right.fetched(),
                        k,
                    );
                    let (cx, cy) = ortho_texel(pat, x, y, k);
                    assert!((tc[0] * WIDTH as f32 - (cx as f32 + 0.5)).abs() < 1e-3);
                    assert!((tc[1] * HEIGHT as f32 - (cy as f32 + 0.5)).abs() < 1e-3);
                }
            }
        }
    }
    for k in 0..DIAG_OFFSETS.len() {
        for i in 0..16 {
            let (ex, ey) = smaa_diag::tile(i);
            let tc = diag_texcoord([3.0, 7.0], [ex as f32, ey as f32], k);
            let (cx, cy) = diag_texel(i, 3, 7, k);
            assert!((tc[0] * WIDTH as f32 - (cx as f32 + 0.5)).abs() < 1e-3);
            assert!((tc[1] * HEIGHT as f32 - (cy as f32 + 0.5)).abs() < 1e-3);
        }
    }
}

#[test]
fn swapping_ends_mirrors_and_swapping_sides_swaps_channels() {
    let t = area_tex();
    for k in 0..ORTHO_OFFSETS.len() {
        for i in 0..16 {
            for y in 0..ORTHO_TILE {
                for x in 0..ORTHO_TILE {
                    let a = ortho(t, i, x, y, k);
                    let m = t.ortho_at(p(i).mirrored(), y, x, k);
                    let m = m.map(f64::from);
                    assert!(near(a, m), "pattern {i} at {x},{y} offset {k}");
                    if k == 0 {
                        let f = t.ortho_at(p(i).flipped(), x, y, 0);
                        let f = [f64::from(f[1]), f64::from(f[0])];
                        assert!(near(a, f), "pattern {i} at {x},{y}");
                    }
                }
            }
        }
    }
}

#[test]
fn no_crossing_edge_no_area_and_code_2_stays_empty() {
    let t = area_tex();
    for k in 0..ORTHO_OFFSETS.len() {
        for y in 0..ORTHO_TILE {
            for x in 0..ORTHO_TILE {
                assert_eq!(ortho(t, 0, x, y, k), [0.0, 0.0]);
            }
        }
        for j in 0..SUBTEX_ROWS {
            for c in 0..WIDTH / 2 {
                let tile_col = c / ORTHO_TILE;
                let tile_row = j / ORTHO_TILE;
                if tile_col == 2 || tile_row == 2 {
                    assert_eq!(t.at(c, SUBTEX_ROWS * k + j), [0.0, 0.0]);
                }
            }
        }
    }
    // The diagonal half below its five offsets is unused.
    for y in DIAG_OFFSETS.len() * SUBTEX_ROWS..HEIGHT {
        for x in WIDTH / 2..WIDTH {
            assert_eq!(t.at(x, y), [0.0, 0.0]);
        }
    }
}

#[test]
fn a_z_of_slope_1_over_n_holds_the_trapezoids() {
    // Pattern 9 (down at the left, up at the right), offset 0: the line from
    // (0, -1/2) to (n, 1/2). Pixel l covers heights -1/2 + l/n .. -1/2 +
    // (l+1)/n: a trapezoid of area |(2l + 1) / (2n) - 1/2| on the side it
    // lies, or, for the centre of an odd n, two triangles of 1 / (8n).
    let t = area_tex();
    for y in 0..ORTHO_TILE {
        for x in 0..ORTHO_TILE {
            let (l, r) = ((x * x) as f64, (y * y) as f64);
            let n = l + r + 1.0;
            let want = if 2.0 * (l + 1.0) <= n {
                [0.5 - (2.0 * l + 1.0) / (2.0 * n), 0.0]
            } else if 2.0 * l >= n {
                [0.0, (2.0 * l + 1.0) / (2.0 * n) - 0.5]
            } else {
                [1.0 / (8.0 * n), 1.0 / (8.0 * n)]
            };
            assert!(near(ortho(t, 9, x, y, 0), want), "l {l} r {r}");
        }
    }
}

#[test]
fn l_shapes_and_smoothed_u_shapes_have_their_hand_computed_areas() {
    let t = area_tex();
    // L (pattern 1), distances 0 and 9: from (0, -1/2) to (5, 0), the first
    // pixel spans heights -1/2 .. -0.4.
    assert!(near(ortho(t, 1, 0, 3, 0), [0.45, 0.0]));
    // Its far half holds nothing.
    assert!(near(ortho(t, 1, 3, 0, 0), [0.0, 0.0]));
    // U (pattern 3) of length 1: two triangles of 1/8, each softened toward
    // sqrt(2 / 8) / 2 = 1/4 by 1 - 1/32.
    let half = 0.25 + (0.125 - 0.25) / 32.0;
    assert!(near(ortho(t, 3, 0, 0, 0), [2.0 * half, 0.0]));
    // Past 32 pixels no softening: l = 16, r = 25.
    let plain = revector::area(p(3), 16.0, 25.0, 0.0, None);
    assert!(near(ortho(t, 3, 4, 5, 0), plain));
    // A subpixel offset lifts the L: at offset -0.25 its end sits at -3/4.
    let k = 1;
    assert_eq!(ORTHO_OFFSETS[k], -0.25);
    // From (0, -3/4) to (5, 0): the first pixel spans -0.75 .. -0.6.
    assert!(near(ortho(t, 1, 0, 3, k), [0.675, 0.0]));
}

#[test]
fn diagonal_tiles_hold_the_clean_diagonal() {
    let t = area_tex();
    for r in 0..DIAG_TILE {
        for l in 0..DIAG_TILE {
            let (x, y) = diag_texel(3, l, r, 0);
            assert!(near(t.at(x, y), [0.5, 0.0]));
        }
    }
}

/// A rising staircase in an image whose rows run top to bottom (Vulkan's
/// framebuffer and texture order, NDC y down with a positive viewport
/// height): white below row 3 for x < 2, below row 2 for 2 <= x < 12, below
/// row 1 after. The line of top edgels in row 2 ends with a crossing edge on
/// its own row at the left and on the row above at the right: pattern 9, a Z
/// rising to the right, whose silhouette runs from the middle of row 2 at
/// x = 2 to the middle of row 1 at x = 12.
#[test]
fn vulkan_rows_hold_the_z_of_a_rising_staircase() {
    let (w, h) = (16, 5);
    let ground = |x: usize| match x {
        0..=1 => 3,
        2..=11 => 2,
        _ => 1,
    };
    let px: Vec<[f32; 4]> = (0..h)
        .flat_map(|y| {
            (0..w).map(move |x| {
                if y >= ground(x) {
                    [1.0, 1.0, 1.0, 1.0]
                } else {
                    [0.0, 0.0, 0.0, 1.0]
                }
            })
        })
        .collect();
    let img = Image::new(w, h, &px).expect("sizes match");
    let edges = smaa_luma_edges(&img, Preset::High.threshold(), LocalContrast::PerEdge)
        .expect("valid threshold");
    for x in 0..w {
        assert_eq!(edges.at(x, 2).top, (2..12).contains(&x), "x {x}");
    }
    // The crossing edges as the blending pass fetches them: left edgels at
    // the centre of the leftmost pixel and of the pixel past the right end,
    // a quarter pixel toward smaller v (the row above in Vulkan, as in D3D).
    let e1 = edges.bilinear(Channel::Left, 2.5, 2.5 - 0.25);
    let e2 = edges.bilinear(Channel::Left, 12.5, 2.5 - 0.25);
    assert_eq!((e1, e2), (0.75, 0.25));
    let bytes = area_tex_rg8();
    let read = |l: usize, r: usize| {
        let sq = [(l as f32).sqrt(), (r as f32).sqrt()];
        let tc = ortho_texcoord(sq, e1, e2, 0);
        let (x, y) = (
            (tc[0] * WIDTH as f32) as usize,
            (tc[1] * HEIGHT as f32) as usize,
        );
        (
            y,
            [bytes[2 * (y * WIDTH + x)], bytes[2 * (y * WIDTH + x) + 1]],
        )
    };
    // Pixel (2, 2), distances 0 and 9: the silhouette at heights 2.5 .. 2.4
    // leaves the top 0.45 of the white pixel above it, black: the pixel takes
    // 0.45 (115 / 255) of the colour above (.r). Read from row 19 from the
    // top: tile row 1 (e2 = 0.25) plus sqrt(9).
    assert_eq!(read(0, 9), (19, [115, 0]));
    // Pixel (11, 2), distances 9 and 0: the silhouette at 1.6 .. 1.5 dips
    // 0.45 into the black pixel above, which takes the white (.g); row 16.
    assert_eq!(read(9, 0), (16, [0, 115]));
    // Counting rows from the bottom (a GL-style flip) reads another table.
    let flipped = 2 * ((HEIGHT - 1 - 19) * WIDTH + 48);
    assert_ne!([bytes[flipped], bytes[flipped + 1]], [115, 0]);
    // And the image flipped upside down is the falling Z (pattern 6), whose
    // first pixel blends the other way: the orientation decides the channel.
    assert!(near(ortho(area_tex(), 6, 0, 3, 0), [0.0, 0.45]));
}

#[test]
fn offset_0_agrees_with_mlaa_where_both_reach() {
    // One geometry in two layouts: MLAA's linear 9 x 9 tiles and SMAA's
    // squared 16 x 16 ones hold the same areas at the distances both store
    // (0, 1, 4), but for the U shapes SMAA softens.
    let mlaa = crate::aa::mlaa_area::MlaaAreaTex::generate();
    let t = area_tex();
    for i in 0..16 {
        for y in 0..3 {
            for x in 0..3 {
                let a = t.ortho_at(p(i), x, y, 0);
                let b = mlaa.area(p(i), x * x, y * y).expect("in reach");
                if i == 3 || i == 12 {
                    assert!(a[0] + a[1] > b[0] + b[1], "pattern {i} at {x},{y}");
                } else {
                    assert_eq!(a, b, "pattern {i} at {x},{y}");
                }
            }
        }
    }
}
