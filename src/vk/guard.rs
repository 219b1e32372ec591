//! A guard that destroys a Vulkan object (or several) unless set-up keeps it:
//! a constructor that makes objects step by step wraps each in a `Guard`, and
//! an early return (`?`) then frees what was made instead of leaking it.

use std::ops::{Deref, DerefMut};

use super::context::Context;
use super::memory::{Buffer, Image};
use super::pipeline::Pipeline;

/// Something that frees its Vulkan objects explicitly (after the GPU is done).
pub trait Destroy {
    fn destroy(&mut self, ctx: &Context);
}

impl Destroy for Pipeline {
    fn destroy(&mut self, ctx: &Context) {
        Pipeline::destroy(self, ctx)
    }
}

impl Destroy for Buffer {
    fn destroy(&mut self, ctx: &Context) {
        Buffer::destroy(self, ctx)
    }
}

impl Destroy for Image {
    fn destroy(&mut self, ctx: &Context) {
        Image::destroy(self, ctx)
    }
}

impl<T: Destroy> Destroy for Vec<T> {
    fn destroy(&mut self, ctx: &Context) {
        for t in self.iter_mut() {
            t.destroy(ctx);
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
