//! The engine on the device (nprt-gpu's wgpu runtime): matrix products and their operands, in
//! f32 (`products::dense_products`, gemm's epilogues) and on f16 operands
//! (`products::half_layers`: the f16 weight layout, rows padded to 16, and the product on
//! tensor cores where the adapter has them; `products::half_mlp`: a whole MLP's forward pass in
//! one dispatch), with the codes the shaders read for activations and losses; the layers
//! that are not a design's own (`layers`: where a dense layer's or a convolution's tensors lie
//! in a flat parameter buffer, convolutions and pooling with their adjoints, gradients summed
//! over chunks of rows); and the kernel list with Adam's. The CPU's twin is `cpu/matmul.rs`.

pub mod kernels;
pub mod layers;
pub mod products;

pub use nprt_gpu::KernelSource;

/// The kernel in `shaders/DIR/NAME.wgsl`, after the shared `shaders/DIR/PART.wgsl` files listed
/// (those with `enable` directives first: WGSL takes them only before any declaration); with
/// `as "OTHER"`, named OTHER (a main file under another epilogue).
#[macro_export]
macro_rules! kernel {
    ($dir:ident / $name:literal $(, $pdir:ident / $part:literal)*) => {
        $crate::kernel!($dir / $name as $name $(, $pdir / $part)*)
    };
    ($dir:ident / $file:literal as $name:literal $(, $pdir:ident / $part:literal)*) => {
        $crate::gpu::KernelSource {
            name: $name,
            wgsl: concat!(
                $(include_str!(concat!("shaders/", stringify!($pdir), "/", $part, ".wgsl")),)*
                include_str!(concat!("shaders/", stringify!($dir), "/", $file, ".wgsl"))
            ),
        }
    };
}
