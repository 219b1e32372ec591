//! Pure-math skin shading building blocks (no Vulkan).
//!
//! Everything here is deterministic CPU code so that the GPU passes can be
//! checked against it: the diffusion profile and its exact line integrals,
//! the separable subsurface-scattering kernel of Jimenez's thesis (eq. 6.1),
//! the transmittance function (eq. 5.12), the Beckmann look-up texture used
//! by the Kelemen/Szirmay-Kalos specular, and a CPU reference of the two
//! screen-space SSS passes.

pub mod beckmann;
pub mod card;
pub mod jittered;
pub mod kernel;
pub mod poisson;
pub mod profile;
pub mod screen_ref;
pub mod separable_ref;
pub mod ssg;
pub mod ssg_ref;
pub mod texel;
pub mod transmittance;
pub mod tsd_ref;
