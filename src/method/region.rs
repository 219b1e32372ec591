//! The SSS region as the methods and the frame name it. Its math is pure and
//! lives in [`crate::view::region`] beside the view's scale; nothing of it
//! needs a GPU type (the frame turns the rectangles into Vulkan scissors,
//! `render::groups::scissors`). Re-exported here so that every method names its
//! region through its own layer.
pub use crate::view::region::{
    cluster_bounds, footprint, scene_region, skin_region, tile_cover, widen, Footprint, PixelRect,
    ReachScale, RegionMode, RegionView, BILINEAR_MARGIN_PX, CLUSTER_CELLS, TILE_PX,
};
