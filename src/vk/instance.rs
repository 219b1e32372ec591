//! The Vulkan instance: the loader, API 1.3, debug utils (object names and
//! labels), and when validation is asked for the Khronos layer with
//! synchronization validation and a messenger into the validation log.

use std::ffi::CStr;

use anyhow::{anyhow, bail, Context as _, Result};
use ash::{ext, vk};

use super::messenger::{Messenger, ValidationLog};
use super::undo::Undo;

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// The loader and the instance, with the messenger when validating.
pub struct Instance {
    pub entry: ash::Entry,
    pub raw: ash::Instance,
    messenger: Option<Messenger>,
}

impl Instance {
    /// An instance; with `validate`, the validation layer and a messenger into
    /// `log` (which must outlive the instance), listening from the instance's
    /// own creation on.
    pub fn new(validate: bool, log: &ValidationLog) -> Result<Self> {
        // SAFETY: loading the system Vulkan loader; failure is reported as an error.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| {
            anyhow!("no Vulkan loader found ({e}); install libvulkan1 and a driver (mesa-vulkan-drivers for lavapipe)")
        })?;

        let app_name = c"dermis";
        let app_info = vk::ApplicationInfo::default()
            .application_name(app_name)
            .application_version(1)
            .engine_name(app_name)
            .api_version(vk::API_VERSION_1_3);

        let mut layers: Vec<*const i8> = Vec::new();
        let mut extensions: Vec<*const i8> = vec![ext::debug_utils::NAME.as_ptr()];
        if validate {
            let available = unsafe { entry.enumerate_instance_layer_properties() }?;
            let have = available
                .iter()
                .any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
            if !have {
                bail!("validation requested but VK_LAYER_KHRONOS_validation is not installed (Debian package vulkan-validationlayers)");
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ext::validation_features::NAME.as_ptr());
        }

        // Synchronization validation is off by default in the layer: turn it on.
        let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
        let mut messenger_info = log.messenger_info();
        let mut create_info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if validate {
            create_info = create_info
                .push_next(&mut validation_features)
                .push_next(&mut messenger_info);
        }
        let raw = match unsafe { entry.create_instance(&create_info, None) } {
            Ok(i) => i,
            Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => bail!(
                "no Vulkan device found: the Vulkan loader found no driver (install mesa-vulkan-drivers for lavapipe, or a GPU driver)"
            ),
            Err(e) => bail!("creating the Vulkan instance: {e}"),
        };
        let undo_instance = Undo::new(|| unsafe { raw.destroy_instance(None) });
        let messenger = if validate {
            Some(Messenger::new(&entry, &raw, log).context("creating the validation messenger")?)
        } else {
            None
        };
        undo_instance.disarm();
        Ok(Instance {
            entry,
            raw,
            messenger,
        })
    }

    /// Destroys the messenger, then the instance (a `&self` method: the
    /// owner's set-up undoes it while still reading the instance).
    ///
    /// # Safety
    /// Once, after everything made from the instance is destroyed.
    pub unsafe fn destroy(&self) {
        if let Some(m) = &self.messenger {
            m.destroy();
        }
        self.raw.destroy_instance(None);
    }
}
