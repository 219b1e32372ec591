//! The typed error of the Vulkan boundary: what a Vulkan call, the memory
//! allocator or the set-up test hook returned. Functions of `vk` that only make
//! objects return it ([`VkResult`]); everything above adds `anyhow` context
//! (which object, which pass) with `?` and `.context(..)`.

use std::fmt;

use ash::vk;
use gpu_allocator::AllocationError;

#[derive(Debug)]
pub enum Error {
    /// A Vulkan call returned an error code.
    Vulkan(vk::Result),
    /// gpu-allocator could not allocate (or free) device memory.
    Allocation(AllocationError),
    /// The set-up test hook failed this creation step on purpose
    /// (`Context::fail_creation_after`); names the object.
    Injected(String),
}

pub type VkResult<T> = std::result::Result<T, Error>;

impl Error {
    /// The Vulkan result code, when a Vulkan call failed.
    pub fn vk_result(&self) -> Option<vk::Result> {
        match self {
            Error::Vulkan(r) => Some(*r),
            _ => None,
        }
    }
}

impl From<vk::Result> for Error {
    fn from(r: vk::Result) -> Self {
        Error::Vulkan(r)
    }
}

impl From<AllocationError> for Error {
    fn from(e: AllocationError) -> Self {
        Error::Allocation(e)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // ash's own wording of the code, as before the typed error.
            Error::Vulkan(r) => write!(f, "{r}"),
            Error::Allocation(e) => write!(f, "{e}"),
            Error::Injected(what) => write!(f, "creating {what}: injected failure (test hook)"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Vulkan(r) => Some(r),
            Error::Allocation(e) => Some(e),
            Error::Injected(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_vulkan_code_converts_and_keeps_its_wording() {
        let e: Error = vk::Result::ERROR_OUT_OF_DEVICE_MEMORY.into();
        assert_eq!(e.vk_result(), Some(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY));
        assert_eq!(
            e.to_string(),
            vk::Result::ERROR_OUT_OF_DEVICE_MEMORY.to_string()
        );
        // anyhow context above it keeps the code reachable.
        let a = anyhow::Error::from(e).context("creating image 'x'");
        assert_eq!(
            a.downcast_ref::<Error>().and_then(Error::vk_result),
            Some(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY)
        );
        assert!(format!("{a:#}").starts_with("creating image 'x': "));
    }

    #[test]
    fn an_injected_failure_names_its_object_on_one_line() {
        let e = Error::Injected("buffer 'b'".into());
        assert_eq!(
            e.to_string(),
            "creating buffer 'b': injected failure (test hook)"
        );
        assert_eq!(e.vk_result(), None);
    }
}
