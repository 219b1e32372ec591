// The tests of smaa_search.rs (a file of their own to keep both short).
use super::*;
use std::collections::BTreeSet;

#[test]
fn the_sixteen_fetches_decode() {
    let codes: BTreeSet<usize> = (0..16)
        .map(|b| fetch_code([b & 1 != 0, b & 2 != 0, b & 4 != 0, b & 8 != 0]))
        .collect();
    assert_eq!(codes.len(), 16);
    for c in 0..=32 {
        assert_eq!(decode(c).map(fetch_code), codes.contains(&c).then_some(c));
    }
    // Eq. 10.5: x = 3/4 along the search, y = 7/8 toward the search's row.
    let e = [true, false, true, true];
    let f = |b: bool| f32::from(u8::from(b));
    let x = 0.75;
    let y = 0.875;
    let bilinear =
        (f(e[0]) * (1.0 - x) + f(e[1]) * x) * (1.0 - y) + (f(e[2]) * (1.0 - x) + f(e[3]) * x) * y;
    assert_eq!(bilinear * 32.0, fetch_code(e) as f32);
}

#[test]
fn the_crop_drops_only_zeros_and_the_values_are_0_127_254() {
    let full = computed();
    for y in 0..FULL_HEIGHT {
        for x in 0..FULL_WIDTH {
            if y < FULL_HEIGHT - HEIGHT || x >= WIDTH {
                assert_eq!(full[y * FULL_WIDTH + x], 0, "{x},{y}");
            }
        }
    }
    let t = search_tex();
    assert_eq!(t.bytes.len(), WIDTH * HEIGHT);
    assert!(t.bytes.iter().all(|v| [0, 127, 254].contains(v)));
    assert!(std::ptr::eq(t, search_tex()));
    // Flipped: row 0 holds .g = 1 (both top edgels of both rows set).
    assert_eq!(texel(0.0, 1.0, false), (0, 0));
    assert_eq!(t.bytes[0], 254);
    // A last fetch with no edge at all (.g = 0) clamps into the zero rows.
    assert_eq!(t.lookup(0.0, 0.0, false), 0);
}

/// Two rows of edgels around a line of top edgels: index 0 the row above,
/// 1 the line's own row. Outside the strip there are no edgels.
struct Strip {
    top: [Vec<bool>; 2],
    left: [Vec<bool>; 2],
}

fn get(v: &[bool], i: isize) -> bool {
    usize::try_from(i)
        .ok()
        .and_then(|i| v.get(i))
        .copied()
        .unwrap_or(false)
}

impl Strip {
    /// A fetch's (.r, .g) in 32nds with `near` the pixel weighted 3/4 and
    /// `far` the next one in the search direction.
    fn fetch(&self, near: isize, far: isize) -> (usize, usize) {
        let four = |v: &[Vec<bool>; 2]| {
            fetch_code([
                get(&v[0], far),
                get(&v[0], near),
                get(&v[1], far),
                get(&v[1], near),
            ])
        };
        (four(&self.left), four(&self.top))
    }

    /// The line continues from pixel `from` into `to` (adjacent): `to` has
    /// the line's edgel and no crossing edgel lies between them.
    fn joins(&self, from: isize, to: isize) -> bool {
        let boundary = from.max(to);
        get(&self.top[1], to) && !get(&self.left[1], boundary) && !get(&self.left[0], boundary)
    }
}

/// `SMAASearchXLeft` / `SMAASearchXRight` with the texture: the loop steps
/// two pixels while the fetch shows both line edgels and no crossing one,
/// then the texture says how many pixels of the last pair belong to the line.
fn search(s: &Strip, tex: &SmaaSearchTex, x0: isize, right: bool) -> (isize, (usize, usize)) {
    let dir = if right { 1 } else { -1 };
    let mut near = if right { x0 + 1 } else { x0 };
    let mut e = (0usize, 32usize);
    let mut last = near;
    while (e.1 as f32 / 32.0) > 0.8281 && e.0 == 0 {
        e = s.fetch(near, near + dir);
        last = near;
        near += 2 * dir;
    }
    let n = isize::from(tex.lookup(e.0 as f32 / 32.0, e.1 as f32 / 32.0, right) / STEP);
    // The last pair's pixels that belong: none leaves the end one short of
    // its near pixel.
    (last + dir * (n - 1), e)
}

fn brute(s: &Strip, x0: isize, right: bool) -> isize {
    let dir = if right { 1 } else { -1 };
    let mut end = x0;
    while s.joins(end, end + dir) {
        end += dir;
    }
    end
}

struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        // xorshift64*: deterministic, enough for coverage.
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn the_texture_gives_the_pixels_to_step_back_for_every_ending() {
    // Random strips: the search through the texture must end exactly where a
    // pixel-by-pixel walk does, in both directions, and every one of the 252
    // last fetches that stop a search (all but the four that continue) must
    // have been met.
    let tex = search_tex();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (w, x0) = (48usize, 24isize);
    let mut seen = [BTreeSet::new(), BTreeSet::new()];
    for trial in 0..60_000 {
        let p_line = 0.3 + 0.69 * rng.unit();
        let p_cross = 0.02 + 0.9 * rng.unit();
        // Crossing edgels only from a random distance on: long clean runs
        // that end in dense crossings reach the rarer last fetches.
        let clear = (rng.unit() * 8.0) as isize;
        let mut row = |p: f64, from: isize| {
            (0..w as isize)
                .map(|x| (x - x0).abs() >= from && rng.unit() < p)
                .collect::<Vec<_>>()
        };
        let mut s = Strip {
            top: [row(p_line, 0), row(p_line, 0)],
            left: [row(p_cross, clear), row(p_cross, clear)],
        };
        s.top[1][x0 as usize] = true;
        for (k, right) in [(0, false), (1, true)] {
            let (end, last) = search(&s, tex, x0, right);
            assert_eq!(end, brute(&s, x0, right), "trial {trial}, right {right}");
            seen[k].insert(last);
        }
    }
    assert_eq!(seen[0].len(), 252);
    assert_eq!(seen[1].len(), 252);
}
