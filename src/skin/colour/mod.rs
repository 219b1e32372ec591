//! Facial colour from chromophores (thesis ch. 7): the spectral data, the
//! colorimetry from a reflectance spectrum to linear sRGB, the two-layer
//! skin model's total diffuse reflectance and the skin-colour lookup table
//! indexed by the cube roots of melanin and haemoglobin (eq. 7.7); the
//! local histogram matching of eq. 7.1-7.3 and the appearance rig of eq.
//! 7.4-7.6 that moves a neutral haemoglobin map to any blend of states; the
//! built-in face's rig. Pure math; the renderer does not upload the table
//! or the rig yet.

pub mod colorimetry;
pub mod face;
pub mod histogram;
pub mod layers;
pub mod lut;
pub mod rig;
pub mod spectra;
