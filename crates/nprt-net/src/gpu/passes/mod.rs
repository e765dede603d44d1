//! The backward passes recorded over the layers' forward tapes, and the optimiser's: an MLP's
//! (`mlp_step`, and on f16 operands `half_products`), the light encoder's (`light_encoder`,
//! `cpu/light_encoder.rs`'s backward), the Deep Shading U-Net's forward and backward
//! (`unet`, `cpu/unet.rs`), a hash grid's table (`grid_backward`), and Adam on the device (`device_adam`, the host's
//! `optimiser::Adam`). Uses `layers` and `products` below it.

pub(crate) mod device_adam;
pub(crate) mod grid_backward;
pub(crate) mod half_products;
pub(crate) mod light_encoder;
pub(crate) mod mlp_step;
pub(crate) mod unet;
