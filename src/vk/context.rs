//! Instance, physical-device choice, logical device, queue, allocator and the
//! validation messenger. Headless: no surface, no swapchain.

use std::ffi::{c_void, CStr, CString};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use anyhow::{anyhow, bail, Context as _, Result};
use ash::{ext, vk};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::error::{Error, VkResult};
use super::undo::Undo;

/// How to choose the physical device.
#[derive(Clone, Debug, Default)]
pub enum DeviceChoice {
    /// First discrete GPU, else the first device.
    #[default]
    Auto,
    /// Index in enumeration order.
    Index(usize),
    /// Case-insensitive substring of the device name.
    Name(String),
}

impl std::str::FromStr for DeviceChoice {
    type Err = std::convert::Infallible;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.parse::<usize>() {
            Ok(i) => DeviceChoice::Index(i),
            Err(_) => DeviceChoice::Name(s.to_string()),
        })
    }
}

#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    pub device: DeviceChoice,
    /// Enables VK_LAYER_KHRONOS_validation with synchronization validation.
    pub validate: bool,
    /// Builds every pipeline from the fetch-counting build of its shaders
    /// (tests of the passes' declared work; see shaders/fetch_count.glsl).
    pub count_fetches: bool,
}

/// Facts about the chosen device that the renderer and the report need.
#[derive(Clone, Debug)]
pub struct DeviceFacts {
    pub name: String,
    pub driver: String,
    pub api_version: String,
    pub device_type: String,
    pub timestamp_period_ns: f64,
    pub timestamp_valid_bits: u32,
    pub pipeline_statistics: bool,
    pub occlusion_query_precise: bool,
    pub independent_blend: bool,
    pub max_image_dimension_2d: u32,
    pub max_storage_buffer_range: u32,
    pub min_storage_buffer_offset_alignment: u64,
    pub sub_texel_precision_bits: u32,
    /// Size of the largest device-local memory heap, bytes.
    pub device_local_bytes: u64,
    /// Whether fragment shaders may write storage buffers (enabled when present:
    /// the fetch-counting build of the shaders needs it).
    pub fragment_stores_and_atomics: bool,
    /// Whether shaders may write clip distances (enabled when present:
    /// texture-space diffusion clips its unwrapped meshes with them).
    pub shader_clip_distance: bool,
    /// Samples per pixel a render target may have (`--msaa`): the counts in
    /// the colour, depth and stencil framebuffer sample-count limits alike,
    /// ascending (1 always).
    pub framebuffer_sample_counts: Vec<u32>,
    /// The depth and stencil resolve modes of VK_KHR_depth_stencil_resolve
    /// (core in 1.2; SAMPLE_ZERO is required of both).
    pub depth_resolve_modes: vk::ResolveModeFlags,
    pub stencil_resolve_modes: vk::ResolveModeFlags,
}

/// Validation messages collected by the debug messenger. Any message is an error:
/// callers drain it with [`Context::check_validation`].
pub type MessageLog = Arc<Mutex<Vec<String>>>;

pub struct Context {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub facts: DeviceFacts,
    pub debug_utils: ext::debug_utils::Device,
    debug_instance: Option<(ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    messages: MessageLog,
    // Boxed so the pointer handed to the messenger stays valid.
    _messages_box: Box<MessageLog>,
    pub allocator: Option<Mutex<Allocator>>,
    /// The counters of the fetch-counting build (host-visible), when enabled.
    pub fetch_counts: Option<FetchCounters>,
    pub command_pool: vk::CommandPool,
    pub validation: bool,
    /// Test hook: object creations left before one is made to fail (see
    /// [`Context::fail_creation_after`]); `usize::MAX` when off.
    fail_countdown: AtomicUsize,
    /// Object creations so far (see [`Context::creation_step`]).
    creations: AtomicUsize,
    /// Set once the device and instance are destroyed.
    torn_down: bool,
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    if data.is_null() || user.is_null() {
        return vk::FALSE;
    }
    let data = &*data;
    let msg = if data.p_message.is_null() {
        String::from("(no message)")
    } else {
        CStr::from_ptr(data.p_message)
            .to_string_lossy()
            .into_owned()
    };
    let log = &*(user as *const MessageLog);
    if let Ok(mut v) = log.lock() {
        v.push(format!("[{severity:?} {kind:?}] {msg}"));
    }
    vk::FALSE
}

/// Counters of the fetch-counting build: slot 0 counts invocations, slot
/// 1 + (set * 16 + binding) * 4 + kind counts fetches (shaders/fetch_count.glsl).
pub const FETCH_COUNTERS: u64 = 1 + 4 * 16 * 4;

/// The host-visible counters of the fetch-counting build (the context holds
/// them: every counting pipeline binds them). Raw handles, not a
/// `memory::Buffer`: the buffer type is made through a context, so holding one
/// here would tie the two files in a cycle.
pub struct FetchCounters {
    pub raw: vk::Buffer,
    allocation: gpu_allocator::vulkan::Allocation,
}

impl FetchCounters {
    fn new(ctx: &Context) -> Result<Self> {
        let raw = ctx
            .create("fetch counters", |d| unsafe {
                d.create_buffer(
                    &vk::BufferCreateInfo::default()
                        .size(FETCH_COUNTERS * 4)
                        // Zeroed by vkCmdFillBuffer before each counted pass.
                        .usage(
                            vk::BufferUsageFlags::STORAGE_BUFFER
                                | vk::BufferUsageFlags::TRANSFER_DST,
                        ),
                    None,
                )
            })
            .context("creating the fetch counters")?;
        let undo_buffer = Undo::new(|| unsafe { ctx.device.destroy_buffer(raw, None) });
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        let allocation = ctx
            .allocator()
            .allocate(&gpu_allocator::vulkan::AllocationCreateDesc {
                name: "fetch counters",
                requirements,
                location: gpu_allocator::MemoryLocation::GpuToCpu,
                linear: true,
                allocation_scheme: gpu_allocator::vulkan::AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(Error::from)
            .context("allocating the fetch counters")?;
        // Freed on an early return until the counters own it.
        let slot = std::cell::RefCell::new(Some(allocation));
        let undo_allocation = Undo::new(|| {
            if let Some(a) = slot.borrow_mut().take() {
                let _ = ctx.allocator().free(a);
            }
        });
        {
            let held = slot.borrow();
            let a = held.as_ref().expect("held until the counters own it");
            unsafe { ctx.device.bind_buffer_memory(raw, a.memory(), a.offset()) }
                .map_err(Error::from)
                .context("binding the fetch counters' memory")?;
        }
        undo_allocation.disarm();
        undo_buffer.disarm();
        ctx.name(raw, "fetch counters");
        let allocation = slot.into_inner().expect("held until the counters own it");
        Ok(FetchCounters { raw, allocation })
    }

    /// The counters (after the fence of the submission that wrote them).
    pub fn read(&self) -> Result<Vec<u32>> {
        let bytes = self
            .allocation
            .mapped_slice()
            .context("the fetch counters are not host visible")?;
        Ok(bytemuck::pod_collect_to_vec(
            &bytes[..(FETCH_COUNTERS * 4) as usize],
        ))
    }
}

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

impl Context {
    pub fn new(desc: &ContextDesc) -> Result<Self> {
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
        let mut extensions: Vec<*const i8> = Vec::new();
        if desc.validate {
            let available = unsafe { entry.enumerate_instance_layer_properties() }?;
            let have = available
                .iter()
                .any(|l| l.layer_name_as_c_str().ok() == Some(VALIDATION_LAYER));
            if !have {
                bail!("validation requested but VK_LAYER_KHRONOS_validation is not installed (Debian package vulkan-validationlayers)");
            }
            layers.push(VALIDATION_LAYER.as_ptr());
        }
        extensions.push(ext::debug_utils::NAME.as_ptr());

        // Synchronization validation is off by default in the layer: turn it on.
        let enabled_features = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_features);
        if desc.validate {
            extensions.push(ext::validation_features::NAME.as_ptr());
        }

        let messages: MessageLog = Arc::new(Mutex::new(Vec::new()));
        let messages_box = Box::new(messages.clone());
        let user_ptr = &*messages_box as *const MessageLog as *mut c_void;
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                    | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(user_ptr);

        let mut create_info = vk::InstanceCreateInfo::default()
            .application_info(&app_info)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if desc.validate {
            create_info = create_info
                .push_next(&mut validation_features)
                .push_next(&mut messenger_info);
        }
        let instance = match unsafe { entry.create_instance(&create_info, None) } {
            Ok(i) => i,
            Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => bail!(
                "no Vulkan device found: the Vulkan loader found no driver (install mesa-vulkan-drivers for lavapipe, or a GPU driver)"
            ),
            Err(e) => bail!("creating the Vulkan instance: {e}"),
        };

        let mut ctx = Self::with_instance(
            entry,
            instance,
            desc,
            (messenger_info.message_severity, messenger_info.message_type),
            messages,
            messages_box,
        )?;
        if desc.count_fetches {
            if !ctx.facts.fragment_stores_and_atomics {
                bail!(
                    "device '{}' cannot write storage buffers from fragment shaders: no fetch counting",
                    ctx.facts.name
                );
            }
            ctx.fetch_counts = Some(FetchCounters::new(&ctx)?);
        }
        Ok(ctx)
    }

    /// The messenger, device, allocator and command pool on `instance`. Until
    /// the context owns them, each is destroyed on an early return (`Undo`:
    /// there is no context yet to destroy through), newest first.
    // Long because device creation is one sequence of queries and creation
    // steps over the same physical device.
    fn with_instance(
        entry: ash::Entry,
        instance: ash::Instance,
        desc: &ContextDesc,
        (severity, kinds): (
            vk::DebugUtilsMessageSeverityFlagsEXT,
            vk::DebugUtilsMessageTypeFlagsEXT,
        ),
        messages: MessageLog,
        messages_box: Box<MessageLog>,
    ) -> Result<Self> {
        let undo_instance = Undo::new(|| unsafe { instance.destroy_instance(None) });
        let debug_instance = if desc.validate {
            // A fresh create-info: the instance's own is chained into its pNext.
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(severity)
                .message_type(kinds)
                .pfn_user_callback(Some(debug_callback))
                .user_data(&*messages_box as *const MessageLog as *mut c_void);
            let loader = ext::debug_utils::Instance::new(&entry, &instance);
            let m = unsafe { loader.create_debug_utils_messenger(&info, None) }
                .map_err(Error::from)
                .context("creating the validation messenger")?;
            Some((loader, m))
        } else {
            None
        };
        let undo_messenger = Undo::new(|| {
            if let Some((l, m)) = &debug_instance {
                unsafe { l.destroy_debug_utils_messenger(*m, None) };
            }
        });
        let physical = pick_physical(&instance, &desc.device)?;
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let name = props
            .device_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if props.api_version < vk::API_VERSION_1_3 {
            bail!(
                "device '{name}' supports Vulkan {}.{} but dermis needs 1.3 (synchronization2 and dynamic rendering)",
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version)
            );
        }
        let mut driver_props = vk::PhysicalDeviceDriverProperties::default();
        let mut resolve_props = vk::PhysicalDeviceDepthStencilResolveProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut driver_props)
            .push_next(&mut resolve_props);
        unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
        let driver = format!(
            "{} {}",
            driver_props
                .driver_name_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            driver_props
                .driver_info_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        );

        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let Some((queue_family, family)) = families.iter().enumerate().find(|(_, f)| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        }) else {
            bail!("device '{name}' has no graphics+compute queue");
        };
        let queue_family = queue_family as u32;
        let features = unsafe { instance.get_physical_device_features(physical) };

        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .synchronization2(true)
            .dynamic_rendering(true);
        let base_features = vk::PhysicalDeviceFeatures::default()
            .pipeline_statistics_query(features.pipeline_statistics_query == vk::TRUE)
            .occlusion_query_precise(features.occlusion_query_precise == vk::TRUE)
            // Sum-of-Gaussians SSS writes RT1 unblended and blends RTF in one MRT pass.
            .independent_blend(features.independent_blend == vk::TRUE)
            // The fetch-counting build of the shaders counts with atomics.
            .fragment_stores_and_atomics(features.fragment_stores_and_atomics == vk::TRUE)
            // Texture-space diffusion clips its unwrapped meshes by the view
            // frustum with clip distances (thesis eq. 3.4).
            .shader_clip_distance(features.shader_clip_distance == vk::TRUE)
            .sampler_anisotropy(false);
        let mut features2 = vk::PhysicalDeviceFeatures2::default().features(base_features);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .push_next(&mut features2)
            .push_next(&mut f13);
        let device = unsafe { instance.create_device(physical, &device_info, None) }
            .map_err(Error::from)
            .with_context(|| format!("creating the logical device on '{name}'"))?;
        let undo_device = Undo::new(|| unsafe { device.destroy_device(None) });
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let debug_utils = ext::debug_utils::Device::new(&instance, &device);

        // Dropped before the device on an early return (declared after it).
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(Error::from)
        .context("creating the GPU memory allocator")?;

        let command_pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
        }
        .map_err(Error::from)
        .context("creating the command pool")?;

        let device_type = format!("{:?}", props.device_type);
        let facts = DeviceFacts {
            name,
            driver: driver.trim().to_string(),
            api_version: format!(
                "{}.{}.{}",
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version),
                vk::api_version_patch(props.api_version)
            ),
            device_type,
            timestamp_period_ns: props.limits.timestamp_period as f64,
            timestamp_valid_bits: family.timestamp_valid_bits,
            pipeline_statistics: features.pipeline_statistics_query == vk::TRUE,
            occlusion_query_precise: features.occlusion_query_precise == vk::TRUE,
            independent_blend: features.independent_blend == vk::TRUE,
            max_image_dimension_2d: props.limits.max_image_dimension2_d,
            max_storage_buffer_range: props.limits.max_storage_buffer_range,
            min_storage_buffer_offset_alignment: props.limits.min_storage_buffer_offset_alignment,
            sub_texel_precision_bits: props.limits.sub_texel_precision_bits,
            device_local_bytes: {
                let m = unsafe { instance.get_physical_device_memory_properties(physical) };
                m.memory_heaps_as_slice()
                    .iter()
                    .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
                    .map(|h| h.size)
                    .max()
                    .unwrap_or(0)
            },
            fragment_stores_and_atomics: features.fragment_stores_and_atomics == vk::TRUE,
            shader_clip_distance: features.shader_clip_distance == vk::TRUE,
            framebuffer_sample_counts: {
                let l = &props.limits;
                let both = l.framebuffer_color_sample_counts
                    & l.framebuffer_depth_sample_counts
                    & l.framebuffer_stencil_sample_counts;
                [1u32, 2, 4, 8, 16, 32, 64]
                    .into_iter()
                    .filter(|&n| both.as_raw() & n != 0)
                    .collect()
            },
            depth_resolve_modes: resolve_props.supported_depth_resolve_modes,
            stencil_resolve_modes: resolve_props.supported_stencil_resolve_modes,
        };

        // Everything is made: the context owns (and tears down) it from here.
        undo_device.disarm();
        undo_messenger.disarm();
        undo_instance.disarm();
        let ctx = Context {
            entry,
            instance,
            physical,
            device,
            queue,
            queue_family,
            facts,
            debug_utils,
            debug_instance,
            messages,
            _messages_box: messages_box,
            allocator: Some(Mutex::new(allocator)),
            fetch_counts: None,
            command_pool,
            validation: desc.validate,
            fail_countdown: AtomicUsize::new(usize::MAX),
            creations: AtomicUsize::new(0),
            torn_down: false,
        };
        ctx.name(ctx.queue, "main queue");
        ctx.name(ctx.command_pool, "main command pool");
        Ok(ctx)
    }

    /// Every Vulkan device the instance sees: index, name, type.
    pub fn devices(&self) -> Result<Vec<(usize, String, String)>> {
        let devices = unsafe { self.instance.enumerate_physical_devices() }?;
        Ok(devices
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let p = unsafe { self.instance.get_physical_device_properties(*d) };
                let name = p
                    .device_name_as_c_str()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                (i, name, format!("{:?}", p.device_type))
            })
            .collect())
    }

    /// Names a Vulkan object for validation messages and captures.
    pub fn name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Ok(cname) = CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&cname);
        // Naming is best effort: a failure only loses a label.
        let _ = unsafe { self.debug_utils.set_debug_utils_object_name(&info) };
    }

    pub fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        self.allocator
            .as_ref()
            .expect("allocator used after teardown")
            .lock()
            .expect("allocator mutex poisoned")
    }

    /// Returns every validation message received since the last call as an error.
    pub fn check_validation(&self, when: &str) -> Result<()> {
        let mut v = self.messages.lock().expect("validation log poisoned");
        if v.is_empty() {
            return Ok(());
        }
        let all = std::mem::take(&mut *v);
        bail!(
            "{} validation message(s) {when}:\n{}",
            all.len(),
            all.join("\n")
        )
    }

    /// Tears the context down and reports what teardown revealed: waits for the
    /// device, checks that every memory allocation was freed, destroys the
    /// device while the validation layer still listens (it names every object
    /// left undestroyed, VUID-vkDestroyDevice-device-00378), then the messenger
    /// and the instance. Messages not yet drained are included. `Drop` does the
    /// same for a context that is not finished, without an error to return.
    pub fn finish(mut self) -> Result<()> {
        let problems = self.teardown();
        if problems.is_empty() {
            return Ok(());
        }
        bail!(
            "{} problem(s) at Vulkan teardown:\n{}",
            problems.len(),
            problems.join("\n")
        )
    }

    /// The result of work done with this context, then [`Context::finish`]: a
    /// run reports what its teardown revealed even when the work failed.
    pub fn finish_with<T>(self, result: Result<T>) -> Result<T> {
        match (result, self.finish()) {
            (Ok(v), Ok(())) => Ok(v),
            (Err(e), Ok(())) => Err(e),
            (Ok(_), Err(t)) => Err(t),
            (Err(e), Err(t)) => Err(anyhow!("{e:#}\nand at teardown: {t:#}")),
        }
    }

    /// Destroys everything the context owns; returns the validation messages
    /// received until the instance went (pending ones included) and the
    /// memory allocations nobody freed.
    fn teardown(&mut self) -> Vec<String> {
        self.torn_down = true;
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.command_pool, None);
        }
        if let Some(c) = self.fetch_counts.take() {
            unsafe { self.device.destroy_buffer(c.raw, None) };
            if let Some(a) = self.allocator.as_ref() {
                let _ = a.lock().map(|mut a| a.free(c.allocation));
            }
        }
        let mut problems: Vec<String> = Vec::new();
        if let Some(a) = self.allocator.take() {
            if let Ok(a) = a.into_inner() {
                problems.extend(a.generate_report().allocations.iter().map(|r| {
                    format!(
                        "memory allocation '{}' ({} bytes) was never freed",
                        r.name, r.size
                    )
                }));
            }
            // The allocator (and its memory blocks) goes before the device.
        }
        unsafe { self.device.destroy_device(None) };
        problems.extend(self.take_messages());
        unsafe {
            if let Some((l, m)) = self.debug_instance.take() {
                l.destroy_debug_utils_messenger(m, None);
            }
            self.instance.destroy_instance(None);
        }
        problems
    }

    fn take_messages(&self) -> Vec<String> {
        self.messages
            .lock()
            .map(|mut v| std::mem::take(&mut *v))
            .unwrap_or_default()
    }

    /// Test hook: the creation `n` steps from now (0: the next) fails with an
    /// error, as a driver's out-of-memory would; `None` turns it off. Drives
    /// every error path of set-up (tests/teardown.rs).
    pub fn fail_creation_after(&self, n: Option<usize>) {
        self.fail_countdown
            .store(n.unwrap_or(usize::MAX), Ordering::SeqCst);
    }

    /// Object creations made so far (each call of [`Context::creation_step`]).
    pub fn creations(&self) -> usize {
        self.creations.load(Ordering::SeqCst)
    }

    /// Called before every Vulkan object (or group made in one call) is
    /// created after the device opens: counts it, and fails it when the test
    /// hook says so.
    pub fn creation_step(&self, what: &str) -> VkResult<()> {
        self.creations.fetch_add(1, Ordering::SeqCst);
        let left = self.fail_countdown.load(Ordering::SeqCst);
        if left == usize::MAX {
            return Ok(());
        }
        if left == 0 {
            self.fail_countdown.store(usize::MAX, Ordering::SeqCst);
            return Err(Error::Injected(what.to_string()));
        }
        self.fail_countdown.store(left - 1, Ordering::SeqCst);
        Ok(())
    }

    /// One creation step at the Vulkan boundary: [`Context::creation_step`],
    /// then `make` with the device. Returns the typed error; callers add the
    /// context (which object, for what).
    pub fn create<T>(
        &self,
        what: &str,
        make: impl FnOnce(&ash::Device) -> std::result::Result<T, vk::Result>,
    ) -> VkResult<T> {
        self.creation_step(what)?;
        Ok(make(&self.device)?)
    }

    /// Image format support for the given usage features.
    pub fn format_supports(&self, format: vk::Format, features: vk::FormatFeatureFlags) -> bool {
        let p = unsafe {
            self.instance
                .get_physical_device_format_properties(self.physical, format)
        };
        p.optimal_tiling_features.contains(features)
    }

    /// Whether an optimal-tiling 2D image of `format` with `usage` may have
    /// `samples` samples per pixel (the format's own limit, below the
    /// framebuffer's).
    pub fn format_supports_samples(
        &self,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        samples: u32,
    ) -> bool {
        let p = unsafe {
            self.instance.get_physical_device_image_format_properties(
                self.physical,
                format,
                vk::ImageType::TYPE_2D,
                vk::ImageTiling::OPTIMAL,
                usage,
                vk::ImageCreateFlags::empty(),
            )
        };
        p.is_ok_and(|p| p.sample_counts.as_raw() & samples != 0)
    }

    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        let Ok(cname) = CString::new(name) else {
            return;
        };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&cname);
        unsafe { self.debug_utils.cmd_begin_debug_utils_label(cmd, &label) };
    }

    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        unsafe { self.debug_utils.cmd_end_debug_utils_label(cmd) };
    }
}

fn pick_physical(instance: &ash::Instance, choice: &DeviceChoice) -> Result<vk::PhysicalDevice> {
    let devices =
        unsafe { instance.enumerate_physical_devices() }.context("enumerating Vulkan devices")?;
    if devices.is_empty() {
        bail!("no Vulkan device found; install a driver (mesa-vulkan-drivers gives lavapipe)");
    }
    let names: Vec<(vk::PhysicalDevice, String, vk::PhysicalDeviceType)> = devices
        .iter()
        .map(|&d| {
            let p = unsafe { instance.get_physical_device_properties(d) };
            let n = p
                .device_name_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            (d, n, p.device_type)
        })
        .collect();
    let list = || {
        names
            .iter()
            .enumerate()
            .map(|(i, (_, n, _))| format!("{i}: {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match choice {
        DeviceChoice::Auto => Ok(names
            .iter()
            .find(|(_, _, t)| *t == vk::PhysicalDeviceType::DISCRETE_GPU)
            .unwrap_or(&names[0])
            .0),
        DeviceChoice::Index(i) => names
            .get(*i)
            .map(|d| d.0)
            .ok_or_else(|| anyhow!("no Vulkan device with index {i} (devices: {})", list())),
        DeviceChoice::Name(s) => {
            let s = s.to_lowercase();
            names
                .iter()
                .find(|(_, n, _)| n.to_lowercase().contains(&s))
                .map(|d| d.0)
                .ok_or_else(|| {
                    anyhow!(
                        "no Vulkan device whose name contains '{s}' (devices: {})",
                        list()
                    )
                })
        }
    }
}

impl Drop for Context {
    /// The fallback for a context that was not [finished](Context::finish): the
    /// same teardown; what it reveals goes to stderr when validation is on.
    fn drop(&mut self) {
        if self.torn_down {
            return;
        }
        let problems = self.teardown();
        if self.validation && !problems.is_empty() {
            eprintln!(
                "warning: {} problem(s) at Vulkan teardown:\n{}",
                problems.len(),
                problems.join("\n")
            );
        }
    }
}
