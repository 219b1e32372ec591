//! Facial colour from chromophores (thesis ch. 7): the spectral data, the
//! colorimetry from a reflectance spectrum to linear sRGB, the two-layer
//! skin model's total diffuse reflectance and the skin-colour lookup table
//! indexed by the cube roots of melanin and haemoglobin (eq. 7.7). Pure
//! math; the renderer does not upload the table yet.

pub mod colorimetry;
pub mod layers;
pub mod lut;
pub mod spectra;
