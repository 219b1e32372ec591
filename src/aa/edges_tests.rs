// The tests of edges.rs (a file of their own to keep both short).
use super::*;

fn grey(v: f32) -> [f32; 4] {
    [v, v, v, 1.0]
}

fn image(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> Vec<[f32; 4]> {
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| grey(f(x, y)))
        .collect()
}

/// The pixels whose left / top edgel is set.
fn set(e: &Edges, ch: Channel) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for y in 0..e.height {
        for x in 0..e.width {
            let g = e.at(x, y);
            if match ch {
                Channel::Left => g.left,
                Channel::Top => g.top,
            } {
                out.push((x, y));
            }
        }
    }
    out
}

/// Every detector on one image, MLAA and SMAA at the same threshold.
fn all(img: &Image, t: f32) -> Vec<Edges> {
    vec![
        mlaa_luma_edges(img, t).unwrap(),
        smaa_luma_edges(img, t, LocalContrast::PerEdge).unwrap(),
        smaa_luma_edges(img, t, LocalContrast::Shared).unwrap(),
        smaa_color_edges(img, t, LocalContrast::PerEdge).unwrap(),
    ]
}

#[test]
fn a_vertical_step_gives_one_column_of_left_edgels() {
    let px = image(8, 4, |x, _| if x < 5 { 0.0 } else { 1.0 });
    let img = Image::new(8, 4, &px).unwrap();
    for e in all(&img, MLAA_LUMA_THRESHOLD) {
        assert_eq!(
            set(&e, Channel::Left),
            (0..4).map(|y| (5, y)).collect::<Vec<_>>()
        );
        assert!(set(&e, Channel::Top).is_empty());
    }
}

#[test]
fn a_horizontal_step_gives_one_row_of_top_edgels() {
    // Row 2 is the first bright one: its pixels own the edgels (rows run top
    // to bottom).
    let px = image(6, 5, |_, y| if y < 2 { 0.2 } else { 0.9 });
    let img = Image::new(6, 5, &px).unwrap();
    for e in all(&img, Preset::Ultra.threshold()) {
        assert_eq!(
            set(&e, Channel::Top),
            (0..6).map(|x| (x, 2)).collect::<Vec<_>>()
        );
        assert!(set(&e, Channel::Left).is_empty());
    }
}

#[test]
fn a_checkerboard_has_every_inner_edgel() {
    let px = image(6, 6, |x, y| ((x + y) % 2) as f32);
    let img = Image::new(6, 6, &px).unwrap();
    for e in all(&img, Preset::Low.threshold()) {
        for y in 0..6 {
            for x in 0..6 {
                // The border's outside is the border pixel itself: no edgel.
                assert_eq!(
                    e.at(x, y),
                    Edgel {
                        left: x > 0,
                        top: y > 0
                    },
                    "{x},{y}"
                );
            }
        }
    }
}

#[test]
fn a_weak_edge_beside_a_strong_one_is_masked() {
    // Columns: 0.0 | 0.2 at x = 4 | 1.0 from x = 5. The weak edgel at x = 4
    // (delta 0.2 >= 0.1) has the strong one (0.8) as its right delta: 0.2 is
    // under half of 0.8, so SMAA drops it; MLAA keeps it.
    let px = image(8, 3, |x, _| match x {
        0..=3 => 0.0,
        4 => 0.2,
        _ => 1.0,
    });
    let img = Image::new(8, 3, &px).unwrap();
    let t = Preset::High.threshold();
    let mlaa = mlaa_luma_edges(&img, t).unwrap();
    let cols = |e: &Edges| {
        let mut c: Vec<usize> = set(e, Channel::Left).iter().map(|p| p.0).collect();
        c.sort_unstable();
        c.dedup();
        c
    };
    assert_eq!(cols(&mlaa), vec![4, 5]);
    for mode in [LocalContrast::PerEdge, LocalContrast::Shared] {
        assert_eq!(cols(&smaa_luma_edges(&img, t, mode).unwrap()), vec![5]);
        assert_eq!(cols(&smaa_color_edges(&img, t, mode).unwrap()), vec![5]);
    }
    // At exactly half it stays (the rule is "at least half"): 0.25 beside
    // 0.75 - 0.25 = 0.5.
    let px = image(8, 3, |x, _| match x {
        0..=3 => 0.0,
        4 => 0.25,
        _ => 0.75,
    });
    let img = Image::new(8, 3, &px).unwrap();
    let e = smaa_color_edges(&img, t, LocalContrast::PerEdge).unwrap();
    assert_eq!(cols(&e), vec![4, 5]);
}

#[test]
fn the_shared_maximum_lets_a_top_top_delta_mask_a_left_edgel() {
    // Rows 0..=1 bright (1.0); below, 0.0 left of x = 4 and 0.2 from it. The
    // left edgel of (4, 3) has delta 0.2; its own neighbourhood holds nothing
    // larger, but the top-top delta (row 2 against row 1: 0.8) does.
    let px = image(8, 6, |x, y| match (x, y) {
        (_, 0..=1) => 1.0,
        (0..=3, _) => 0.0,
        _ => 0.2,
    });
    let img = Image::new(8, 6, &px).unwrap();
    let t = Preset::Medium.threshold();
    let per = smaa_luma_edges(&img, t, LocalContrast::PerEdge).unwrap();
    let shared = smaa_luma_edges(&img, t, LocalContrast::Shared).unwrap();
    assert!(per.at(4, 3).left);
    assert!(!shared.at(4, 3).left);
}

#[test]
fn colour_edges_see_what_luma_cannot() {
    // Red against a green of the same luma: no luma edge, a colour edge.
    let g = 0.2126 / 0.7152;
    let px: Vec<[f32; 4]> = (0..8)
        .map(|x| {
            if x < 4 {
                [1.0, 0.0, 0.0, 1.0]
            } else {
                [0.0, g, 0.0, 1.0]
            }
        })
        .collect();
    let img = Image::new(8, 1, &px).unwrap();
    let t = Preset::High.threshold();
    assert!(set(
        &smaa_luma_edges(&img, t, LocalContrast::PerEdge).unwrap(),
        Channel::Left
    )
    .is_empty());
    let c = smaa_color_edges(&img, t, LocalContrast::PerEdge).unwrap();
    assert_eq!(set(&c, Channel::Left), vec![(4, 0)]);
}

#[test]
fn depth_edges_use_the_callers_threshold() {
    let depth: Vec<f32> = (0..12)
        .map(|i| if i % 4 < 2 { 0.5 } else { 0.52 })
        .collect();
    let e = mlaa_depth_edges(&depth, 4, 3, Preset::High.depth_threshold()).unwrap();
    assert_eq!(set(&e, Channel::Left), vec![(2, 0), (2, 1), (2, 2)]);
    let e = mlaa_depth_edges(&depth, 4, 3, 0.05).unwrap();
    assert!(set(&e, Channel::Left).is_empty());
    assert!(mlaa_depth_edges(&depth, 4, 4, 0.01).is_err());
}

#[test]
fn bad_inputs_are_errors() {
    let px = vec![grey(0.0); 6];
    assert!(Image::new(2, 2, &px).is_err());
    assert!(Image::new(0, 6, &px).is_err());
    assert!(Image::new(usize::MAX, 2, &px).is_err());
    let img = Image::new(3, 2, &px).unwrap();
    assert!(mlaa_luma_edges(&img, 0.0).is_err());
    assert!(smaa_luma_edges(&img, f32::NAN, LocalContrast::PerEdge).is_err());
    assert!(smaa_color_edges(&img, -0.1, LocalContrast::Shared).is_err());
}

#[test]
fn bilinear_fetches_weigh_the_edgels() {
    let px = image(4, 3, |x, _| if x < 2 { 0.0 } else { 1.0 });
    let e = mlaa_luma_edges(&Image::new(4, 3, &px).unwrap(), 0.1).unwrap();
    // Left edgels in column 2: a fetch at the centre reads it whole, a
    // quarter pixel toward column 1 reads 0.75 of it, halfway 0.5.
    assert_eq!(e.bilinear(Channel::Left, 2.5, 1.5), 1.0);
    assert_eq!(e.bilinear(Channel::Left, 2.25, 1.5), 0.75);
    assert_eq!(e.bilinear(Channel::Left, 2.0, 1.5), 0.5);
    assert_eq!(e.bilinear(Channel::Top, 2.0, 1.5), 0.0);
}
