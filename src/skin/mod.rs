//! Pure-math skin shading building blocks (no Vulkan).
//!
//! Everything here is deterministic CPU code so that the GPU passes can be
//! checked against it: the diffusion profile and its exact line integrals,
//! the separable subsurface-scattering kernel of Jimenez's thesis (eq. 6.1),
//! the transmittance function (eq. 5.12), the Beckmann look-up texture used
//! by the Kelemen/Szirmay-Kalos specular, each method's pure parts (`ssg`,
//! `jittered`, `poisson`, `tsd`), and the CPU mirrors of the GPU passes
//! (`*_mirror`: the pass repeated operation by operation, so a test can hold
//! the GPU to it per pixel; "reference" names only the ground truth).

pub mod beckmann;
pub mod burley;
pub mod card;
pub mod colour;
pub mod diffusion;
pub mod gather;
pub mod jittered;
pub mod kernel;
pub mod mirror;
pub mod poisson;
pub mod profile;
pub mod screen_mirror;
pub mod separable_mirror;
pub mod ssg;
pub mod ssg_mirror;
pub mod texel;
pub mod tissue;
pub mod transmittance;
pub mod tsd;
pub mod tsd_mirror;
pub mod wrinkles;
