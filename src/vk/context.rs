//! The context every part of dermis works through: the instance, the chosen
//! physical device and the logical device, with the queue, the memory
//! allocator, the command pool, the validation log and the set-up test hook
//! they share, made in that order and torn down in reverse. Headless: no
//! surface, no swapchain. Each part is its own file (instance.rs,
//! physical_device.rs, device.rs, messenger.rs, fault.rs); this one ties them
//! together and owns what they make.

use std::ffi::CString;
use std::sync::Mutex;

use anyhow::{anyhow, bail, Context as _, Result};
use ash::{ext, vk};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::error::{Error, VkResult};
use super::fault::Faults;
use super::instance::Instance;
use super::messenger::ValidationLog;
use super::physical_device::{self, PhysicalDevice};
use super::undo::Undo;

// The device choice and facts live with the physical device; named here too,
// where every caller already finds the context.
pub use super::physical_device::{DeviceChoice, DeviceChoiceError, DeviceFacts};

#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    pub device: DeviceChoice,
    /// Enables VK_LAYER_KHRONOS_validation with synchronization validation.
    pub validate: bool,
    /// Builds every pipeline from the fetch-counting build of its shaders
    /// (tests of the passes' declared work; see shaders/fetch_count.glsl).
    pub count_fetches: bool,
}

pub struct Context {
    pub instance: Instance,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub facts: DeviceFacts,
    pub debug_utils: ext::debug_utils::Device,
    /// Filled by the instance's messenger, which points at it: dropped after
    /// the instance (teardown destroys the instance first).
    log: ValidationLog,
    pub allocator: Option<Mutex<Allocator>>,
    /// The counters of the fetch-counting build (host-visible), when enabled.
    pub fetch_counts: Option<FetchCounters>,
    pub command_pool: vk::CommandPool,
    pub validation: bool,
    /// The set-up test hook (see [`Context::fail_creation_after`]).
    faults: Faults,
    /// Set once the device and instance are destroyed.
    torn_down: bool,
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

impl Context {
    pub fn new(desc: &ContextDesc) -> Result<Self> {
        let log = ValidationLog::default();
        let instance = Instance::new(desc.validate, &log)?;
        let mut ctx = Self::with_instance(instance, log, desc)?;
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

    /// The device, allocator and command pool on `instance`. Until the
    /// context owns them, each is destroyed on an early return (`Undo`: there
    /// is no context yet to destroy through), newest first; `log` outlives
    /// them all (an argument drops after the function's locals).
    fn with_instance(instance: Instance, log: ValidationLog, desc: &ContextDesc) -> Result<Self> {
        let undo_instance = Undo::new(|| unsafe { instance.destroy() });
        let physical = PhysicalDevice::choose(&instance.raw, &desc.device)?;
        let device = super::device::create(&instance.raw, &physical)?;
        let undo_device = Undo::new(|| unsafe { device.destroy_device(None) });
        let queue = unsafe { device.get_device_queue(physical.queue_family, 0) };
        let debug_utils = ext::debug_utils::Device::new(&instance.raw, &device);

        // Dropped before the device on an early return (declared after it).
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.raw.clone(),
            device: device.clone(),
            physical_device: physical.raw,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(Error::from)
        .context("creating the GPU memory allocator")?;

        let command_pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(physical.queue_family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )
        }
        .map_err(Error::from)
        .context("creating the command pool")?;

        // Everything is made: the context owns (and tears down) it from here.
        undo_device.disarm();
        undo_instance.disarm();
        let ctx = Context {
            instance,
            physical: physical.raw,
            device,
            queue,
            queue_family: physical.queue_family,
            facts: physical.facts,
            debug_utils,
            log,
            allocator: Some(Mutex::new(allocator)),
            fetch_counts: None,
            command_pool,
            validation: desc.validate,
            faults: Faults::default(),
            torn_down: false,
        };
        ctx.name(ctx.queue, "main queue");
        ctx.name(ctx.command_pool, "main command pool");
        Ok(ctx)
    }

    /// Every Vulkan device the instance sees: index, name, type.
    pub fn devices(&self) -> Result<Vec<(usize, String, String)>> {
        physical_device::list(&self.instance.raw)
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
        self.log.check(when)
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
        problems.extend(self.log.take());
        unsafe { self.instance.destroy() };
        problems
    }

    /// Test hook: the creation `n` steps from now (0: the next) fails with an
    /// error, as a driver's out-of-memory would; `None` turns it off. Drives
    /// every error path of set-up (tests/teardown.rs).
    pub fn fail_creation_after(&self, n: Option<usize>) {
        self.faults.fail_after(n);
    }

    /// Object creations made so far (each call of [`Context::creation_step`]).
    pub fn creations(&self) -> usize {
        self.faults.creations()
    }

    /// Called before every Vulkan object (or group made in one call) is
    /// created after the device opens: counts it, and fails it when the test
    /// hook says so.
    pub fn creation_step(&self, what: &str) -> VkResult<()> {
        self.faults.step(what)
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
        physical_device::format_supports(&self.instance.raw, self.physical, format, features)
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
        physical_device::format_supports_samples(
            &self.instance.raw,
            self.physical,
            format,
            usage,
            samples,
        )
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
