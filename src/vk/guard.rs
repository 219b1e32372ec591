//! Owning handles for set-up. [`Destroy`] says how a Vulkan object (or a struct
//! of them) is freed; a [`Guard`] owns one while set-up is still making things:
//! an early return (`?`) drops the guard, which frees what it holds, and
//! [`Guard::keep`] hands the finished object to its owner. So a constructor
//! wraps each object as it is made and needs no cleanup code of its own.
//!
//! Freeing at run time stays explicit (`destroy`, after the fence or a
//! wait-idle: see `render::Renderer`'s drop), because a handle cannot know
//! when the GPU is done with it. A guard frees at once, which is right during
//! set-up: every set-up submission waits on its own fence
//! (`Context::one_shot`), so nothing a failed set-up made is still in use.
//!
//! [`super::undo::Undo`] covers the steps before a `Context` exists (instance, device).

use std::ops::{Deref, DerefMut};

use ash::vk;

use super::context::Context;

/// Something that frees its Vulkan objects explicitly (after the GPU is done).
/// Destroying twice, or destroying the null object (`Default`), does nothing.
/// Owners implement it beside their own type (memory.rs, pipeline.rs,
/// profiler.rs...), so this file names none of them and no cycle forms.
pub trait Destroy {
    fn destroy(&mut self, ctx: &Context);
}

impl<T: Destroy> Destroy for Vec<T> {
    fn destroy(&mut self, ctx: &Context) {
        for t in self.iter_mut() {
            t.destroy(ctx);
        }
    }
}

impl<T: Destroy> Destroy for Option<T> {
    fn destroy(&mut self, ctx: &Context) {
        if let Some(mut t) = self.take() {
            t.destroy(ctx);
        }
    }
}

impl<T: Destroy + ?Sized> Destroy for Box<T> {
    fn destroy(&mut self, ctx: &Context) {
        (**self).destroy(ctx)
    }
}

/// Raw handles that set-up makes on their own: each destroy takes the handle
/// and leaves the null one (Vulkan ignores the null handle).
macro_rules! destroy_raw {
    ($($ty:ty => $f:ident),* $(,)?) => {$(
        impl Destroy for $ty {
            fn destroy(&mut self, ctx: &Context) {
                unsafe { ctx.device.$f(std::mem::take(self), None) }
            }
        }
    )*};
}

destroy_raw! {
    vk::ShaderModule => destroy_shader_module,
    vk::DescriptorSetLayout => destroy_descriptor_set_layout,
    vk::PipelineLayout => destroy_pipeline_layout,
    vk::Pipeline => destroy_pipeline,
    vk::DescriptorPool => destroy_descriptor_pool,
    vk::QueryPool => destroy_query_pool,
    vk::Fence => destroy_fence,
    vk::Sampler => destroy_sampler,
}

/// Command buffers come from the context's one pool.
impl Destroy for vk::CommandBuffer {
    fn destroy(&mut self, ctx: &Context) {
        let cmd = std::mem::take(self);
        if cmd != vk::CommandBuffer::null() {
            unsafe { ctx.device.free_command_buffers(ctx.command_pool, &[cmd]) };
        }
    }
}

/// `value`, destroyed on drop unless [`Guard::keep`] takes it out.
pub struct Guard<'c, T: Destroy> {
    ctx: &'c Context,
    value: Option<T>,
}

impl<'c, T: Destroy> Guard<'c, T> {
    pub fn new(ctx: &'c Context, value: T) -> Self {
        Guard {
            ctx,
            value: Some(value),
        }
    }

    /// The value, no longer guarded: its owner destroys it from now on.
    pub fn keep(mut self) -> T {
        self.value
            .take()
            .expect("a guard holds its value until kept")
    }
}

impl<'c, T: Destroy + Default> Guard<'c, T> {
    /// The null object, to fill in field by field.
    pub fn null(ctx: &'c Context) -> Self {
        Guard::new(ctx, T::default())
    }
}

impl<T: Destroy> Deref for Guard<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value
            .as_ref()
            .expect("a guard holds its value until kept")
    }
}

impl<T: Destroy> DerefMut for Guard<'_, T> {
    fn deref_mut(&mut self) -> &mut T {
        self.value
            .as_mut()
            .expect("a guard holds its value until kept")
    }
}

impl<T: Destroy> Drop for Guard<'_, T> {
    fn drop(&mut self) {
        if let Some(mut v) = self.value.take() {
            v.destroy(self.ctx);
        }
    }
}
