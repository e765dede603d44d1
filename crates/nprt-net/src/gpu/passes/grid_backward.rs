//! A hash grid's table gradient on the device (`grid_backward.wgsl`), from the gradient at the
//! inputs its encoding joined: what a track's training step and the radiance cache's share.

use crate::encoding::hash_grid;
use crate::gpu::kernels::GRID_BACKWARD;
use crate::gpu::products::dense_products::DenseProducts;
use crate::gpu::products::operands::Output;
use nprt_gpu::{groups_for, Dispatch, GpuDevice, Span};

/// Threads of `grid_backward` per chunk of rows: one per 64 slots of each level's table.
const GRID_BACKWARD_THREADS: usize = hash_grid::LEVELS * hash_grid::TABLE_SIZE / 64;
/// Chunks of rows `grid_backward` cuts a batch into at most, each with its own copy of the
/// tables (512 KiB): 32 MiB at most.
const GRID_CHUNKS: usize = 64;

/// The rows a grid's gradient comes from: `rows` of `features`, whose inputs are `width` wide,
/// the grid's encoding after the first `count`.
pub struct GridRows<'a> {
    pub features: &'a wgpu::Buffer,
    pub rows: usize,
    pub count: usize,
    pub width: usize,
}

/// Records the gradient of the grid at `table` (its span of the parameters) into the same span
/// of `grads`, from the gradient `dx` at the inputs of `at`, the grid's level resolutions in
/// `resolutions`: summed per chunk of rows in a fixed order (at most [`GRID_CHUNKS`], each of
/// at least 256 rows), then over the chunks.
pub fn record_grid_backward(
    gpu: &GpuDevice,
    plan: &mut Vec<Dispatch>,
    at: GridRows,
    [resolutions, dx, grads]: [&wgpu::Buffer; 3],
    table: Span,
) {
    let chunk = at.rows.div_ceil(GRID_CHUNKS).max(256);
    let chunks = at.rows.div_ceil(chunk);
    let partial = gpu.buffer(chunks * table.len);
    plan.push(gpu.prepare(
        &GRID_BACKWARD,
        &[at.rows, at.count, at.width, chunk].map(|v| v as u32),
        &[at.features, resolutions, dx, &partial],
        groups_for(chunks * GRID_BACKWARD_THREADS),
    ));
    let d_table = Output::to(grads, table.offset, table.len);
    gpu.column_sum(plan, &partial, chunks, table.len, None, d_table);
}
