//! Skin as two layers (thesis ch. 7.6: "the total diffuse reflectance
//! predicted by the two-layered translucent skin model"; Donner and Jensen
//! 2006, Donner et al. 2008): an epidermis of melanin, a little blood and
//! baseline tissue over a semi-infinite dermis of blood and baseline tissue,
//! both scattering. Per wavelength, in mm^-1:
//!
//! - baseline tissue: sigma_a = 0.0244 + 8.53 exp(-(lambda - 154) / 66.2)
//!   (Jacques' skin baseline, OMLC);
//! - eumelanin 6.6e10 lambda^-3.33, pheomelanin 2.9e14 lambda^-4.75 per unit
//!   melanosome fraction, mixed by the eumelanin share beta_m;
//! - blood: 2.303 e x / 64 500 with x = 150 g/L of haemoglobin and e Prahl's
//!   molar extinction (`spectra`), 75% oxygenated (cm^-1, over 10 for mm^-1);
//! - epidermis: C_m melanin + C_he blood + the rest baseline; dermis: C_hd
//!   blood + the rest baseline;
//! - reduced scattering: epidermis 14.74 lambda^-0.22 + 2.2e11 lambda^-4,
//!   the dermis half of it; the epidermis 0.25 mm thick; refractive index 1.4.
//!
//! The totals come from the diffusion approximation in closed form: the
//! multipole slab of Donner and Jensen 2005 integrated over the plane (each
//! dipole term's integral of z (1 + s d) e^(-s d) / d^3 over the plane is
//! 2 pi sgn(z) e^(-s |z|)), the semi-infinite dermis's dipole (Jensen et al.
//! 2001's R_d), and the layers added as Kubelka-Munk does at zero spatial
//! frequency, with the epidermis lit from above and from below apart:
//! R = R1_down + T1_down R2 T1_up / (1 - R1_up R2). (A stack whose epidermis
//! is optically its dermis must reflect as one deep layer: this form does,
//! within 1%; taking one R1 and T1 for both directions does not,
//! `tests::an_epidermis_like_its_dermis_changes_nothing`.)

use super::colorimetry::Spectrum;
use super::spectra::{wavelength_nm, HBO2_EPS_5NM, HB_EPS_5NM};

/// Epidermis thickness (mm).
pub const EPIDERMIS_MM: f64 = 0.25;
/// Refractive index of both layers.
pub const ETA: f64 = 1.4;
/// Oxygenated share of the blood's haemoglobin.
pub const OXYGENATION: f64 = 0.75;
/// Haemoglobin per litre of blood (g) and its molar mass (g/mol).
const HAEMOGLOBIN_G_PER_L: f64 = 150.0;
const HAEMOGLOBIN_G_PER_MOL: f64 = 64_500.0;
/// Dipole pairs on each side of the central one in a slab's multipole
/// (converged to 2e-4 in linear RGB beyond two).
const MULTIPOLE_PAIRS: i32 = 5;

/// The chromophores of one point of skin (thesis Table 7.1's parameters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chromophores {
    /// Melanin volume fraction of the epidermis, C_m (0-0.5).
    pub melanin: f64,
    /// Eumelanin's share of it, beta_m (0-1; the thesis' table: 0.61).
    pub eumelanin: f64,
    /// Blood volume fraction of the epidermis, C_he (0-0.1; the table: 0.25 C_hd).
    pub epidermal_blood: f64,
    /// Blood volume fraction of the dermis, C_hd (0-0.32).
    pub dermal_blood: f64,
}

/// Absorption of chromophore-free tissue (mm^-1).
pub fn baseline_absorption(nm: f64) -> f64 {
    0.0244 + 8.53 * (-(nm - 154.0) / 66.2).exp()
}

/// Absorption of melanosomes of eumelanin share `eumelanin` (mm^-1).
pub fn melanin_absorption(nm: f64, eumelanin: f64) -> f64 {
    let eu = 6.6e10 * nm.powf(-3.33);
    let pheo = 2.9e14 * nm.powf(-4.75);
    eumelanin * eu + (1.0 - eumelanin) * pheo
}

/// Absorption of whole blood at sample `i` (mm^-1).
pub fn blood_absorption(i: usize) -> f64 {
    let per_cm = |eps: f32| 2.303 * eps as f64 * HAEMOGLOBIN_G_PER_L / HAEMOGLOBIN_G_PER_MOL;
    (OXYGENATION * per_cm(HBO2_EPS_5NM[i]) + (1.0 - OXYGENATION) * per_cm(HB_EPS_5NM[i])) / 10.0
}

/// Reduced scattering of the epidermis (mm^-1); the dermis scatters half.
pub fn epidermis_scattering(nm: f64) -> f64 {
    14.74 * nm.powf(-0.22) + 2.2e11 * nm.powi(-4)
}

/// A layer's optics at one wavelength (mm^-1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    pub absorption: f64,
    pub scattering: f64,
}

impl Medium {
    fn extinction(&self) -> f64 {
        self.absorption + self.scattering
    }
    fn albedo(&self) -> f64 {
        self.scattering / self.extinction()
    }
    fn transport(&self) -> f64 {
        (3.0 * self.absorption * self.extinction()).sqrt()
    }
    /// The extrapolation distance of a boundary of relative index `eta`.
    fn extrapolation(&self, eta: f64) -> f64 {
        2.0 * boundary_a(eta) / (3.0 * self.extinction())
    }
}

/// The epidermis and the dermis of `c` at sample `i`.
pub fn layers(c: &Chromophores, i: usize) -> (Medium, Medium) {
    let nm = wavelength_nm(i);
    let (base, blood) = (baseline_absorption(nm), blood_absorption(i));
    let epidermis = Medium {
        absorption: c.melanin * melanin_absorption(nm, c.eumelanin)
            + c.epidermal_blood * blood
            + (1.0 - c.melanin - c.epidermal_blood) * base,
        scattering: epidermis_scattering(nm),
    };
    let dermis = Medium {
        absorption: c.dermal_blood * blood + (1.0 - c.dermal_blood) * base,
        scattering: 0.5 * epidermis_scattering(nm),
    };
    (epidermis, dermis)
}

/// The diffuse Fresnel reflectance's boundary term A = (1 + F_dr) / (1 -
/// F_dr), F_dr from Egan and Hilgeman's fit (eta >= 1).
pub fn boundary_a(eta: f64) -> f64 {
    let f = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    (1.0 + f) / (1.0 - f)
}

/// Total diffuse reflectance of a semi-infinite medium under a boundary of
/// relative index `eta` (Jensen et al. 2001).
pub fn semi_infinite_reflectance(m: &Medium, eta: f64) -> f64 {
    let a = m.albedo();
    let s = (3.0 * (1.0 - a)).sqrt();
    0.5 * a * (1.0 + (-4.0 / 3.0 * boundary_a(eta) * s).exp()) * (-s).exp()
}

/// Total diffuse reflectance and transmittance of a slab `d` mm thick, lit
/// on the side whose boundary has relative index `eta_lit`, the other
/// `eta_far` (the multipole, integrated over the plane).
pub fn slab(m: &Medium, d: f64, eta_lit: f64, eta_far: f64) -> (f64, f64) {
    let (zb0, zbd) = (m.extrapolation(eta_lit), m.extrapolation(eta_far));
    let (l, s, a) = (1.0 / m.extinction(), m.transport(), m.albedo());
    let term = |z: f64| z.signum() * (-s * z.abs()).exp();
    let (mut r, mut t) = (0.0, 0.0);
    for i in -MULTIPOLE_PAIRS..=MULTIPOLE_PAIRS {
        let shift = 2.0 * i as f64 * (d + zb0 + zbd);
        let (zr, zv) = (shift + l, shift - l - 2.0 * zb0);
        r += term(zr) - term(zv);
        t += term(d - zr) - term(d - zv);
    }
    (0.5 * a * r, 0.5 * a * t)
}

/// Total diffuse reflectance of an epidermis `EPIDERMIS_MM` thick over a
/// semi-infinite dermis (module docs: the two-direction adding).
pub fn stack(epi: &Medium, derm: &Medium) -> f64 {
    // The interface between the layers matches (one index): A = A(1).
    let (r_down, t_down) = slab(epi, EPIDERMIS_MM, ETA, 1.0);
    let (r_up, t_up) = slab(epi, EPIDERMIS_MM, 1.0, ETA);
    let r2 = semi_infinite_reflectance(derm, 1.0);
    r_down + t_down * r2 * t_up / (1.0 - r_up * r2)
}

/// Total diffuse reflectance of skin `c` at sample `i`.
pub fn reflectance_at(c: &Chromophores, i: usize) -> f64 {
    let (epi, derm) = layers(c, i);
    stack(&epi, &derm)
}

/// The reflectance spectrum of skin `c`.
pub fn reflectance(c: &Chromophores) -> Spectrum {
    std::array::from_fn(|i| reflectance_at(c, i))
}

#[cfg(test)]
mod tests {
    use super::*;

    // A slab much thicker than its transport length reflects as the
    // semi-infinite medium and transmits nothing.
    #[test]
    fn a_thick_slab_is_the_semi_infinite_medium() {
        let m = Medium {
            absorption: 0.05,
            scattering: 4.0,
        };
        let (r, t) = slab(&m, 200.0, ETA, 1.0);
        assert!((r - semi_infinite_reflectance(&m, ETA)).abs() < 1e-9, "{r}");
        assert!(t.abs() < 1e-9, "{t}");
        let (thin_r, thin_t) = slab(&m, 0.25, ETA, 1.0);
        assert!(thin_r < r && thin_t > 0.1, "{thin_r} {thin_t}");
    }

    // The physical invariant of the layering: an epidermis optically the
    // same as its dermis, over that dermis, is one deep layer under the air's
    // boundary. The two-direction adding meets it within 1% over skin's
    // range of coefficients (the epidermis at least one transport length
    // thick: sigma_t >= 4 mm^-1, as skin's reduced scattering keeps it from
    // 380 to 780 nm); one R1 and T1 for both directions overshoots by 13%.
    #[test]
    fn an_epidermis_like_its_dermis_changes_nothing() {
        for (absorption, scattering) in [(0.02, 5.0), (0.03, 4.4), (0.2, 8.0), (2.0, 8.0)] {
            let m = Medium {
                absorption,
                scattering,
            };
            let deep = semi_infinite_reflectance(&m, ETA);
            let stack = stack(&m, &m);
            // The one-direction adding, for the check that the test can fail.
            let (r_down, t_down) = slab(&m, EPIDERMIS_MM, ETA, 1.0);
            let r2 = semi_infinite_reflectance(&m, 1.0);
            let same = r_down + t_down * r2 * t_down / (1.0 - r_down * r2);
            println!("sigma_a {absorption}, sigma_s' {scattering}: deep {deep:.4}, stacked {stack:.4}, one-direction {same:.4}");
            assert!((stack / deep - 1.0).abs() < 0.01, "{stack} vs {deep}");
            if absorption < 0.1 {
                assert!(
                    same / deep - 1.0 > 0.05,
                    "the check can fail: {same} vs {deep}"
                );
            }
        }
    }

    // Spot values of the coefficients against their formulas' published
    // anchors: Prahl's table at 400 nm (266 232 and 223 296 cm^-1/M) through
    // 2.303 e 150 / 64 500, and the scattering's lambda^-4 Rayleigh part.
    #[test]
    fn the_coefficients_at_400_nm() {
        let i = 4;
        assert_eq!(wavelength_nm(i), 400.0);
        let oxy = 2.303 * 266_232.0 * 150.0 / 64_500.0 / 10.0;
        let deoxy = 2.303 * 223_296.0 * 150.0 / 64_500.0 / 10.0;
        assert!((blood_absorption(i) - (0.75 * oxy + 0.25 * deoxy)).abs() < 1e-9);
        assert!((deoxy - 119.593).abs() < 1e-3, "{deoxy}");
        assert!((epidermis_scattering(400.0) - 12.54).abs() < 0.01);
        assert!((boundary_a(ETA) - 3.2507).abs() < 1e-3);
        assert!((boundary_a(1.0) - 1.0032).abs() < 1e-3);
    }
}
