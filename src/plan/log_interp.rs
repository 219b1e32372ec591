//! Interpolation between the stored frames' scales: linear in ln(px/mm),
//! clamped to the ends (`cost`: a kernel's size on screen is linear in the
//! scale, so counts move smoothly in its logarithm).

/// Where `x` falls among ascending `xs`: indices of the bracketing samples and
/// the weight of the second, linear in ln(x), clamped to the ends.
pub fn bracket(xs: &[f64], x: f64) -> (usize, usize, f64) {
    let n = xs.len();
    if n == 1 || x <= xs[0] {
        return (0, 0, 0.0);
    }
    if x >= xs[n - 1] {
        return (n - 1, n - 1, 0.0);
    }
    let j = xs.iter().position(|&v| v >= x).unwrap_or(n - 1);
    let i = j - 1;
    let t = (x.ln() - xs[i].ln()) / (xs[j].ln() - xs[i].ln());
    (i, j, t)
}

pub fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + (b - a) * t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_in_log_scale_and_clamps_at_the_ends() {
        let xs = [1.0, 4.0, 16.0];
        assert_eq!(bracket(&xs, 0.5), (0, 0, 0.0));
        assert_eq!(bracket(&xs, 20.0), (2, 2, 0.0));
        let (i, j, t) = bracket(&xs, 2.0);
        assert_eq!((i, j), (0, 1));
        assert!((t - 0.5).abs() < 1e-12, "{t}");
        assert_eq!(bracket(&[3.0], 7.0), (0, 0, 0.0));
        assert_eq!(lerp(2.0, 4.0, 0.25), 2.5);
    }
}
