// How a subgroup's 16 × 16 tile of f32 sums (a cooperative matrix) leaves a tensor-core
// product: stored through the subgroup's share of workgroup memory, after which each of its 32
// lanes hands 8 of the values to the kernel's `finish(i, j, sum)` (its epilogue), which skips
// the columns past its output's. Every lane of the workgroup must call it, in the same order.

var<workgroup> staged: array<f32, 1024>;

// One 16 × 16 tile of sums from (row, col) through the subgroup's staging.
fn drain(m: coop_mat16x16<f32, C>, sg: u32, lane: u32, row: u32, col: u32) {
    let base = sg * 256u;
    workgroupBarrier();
    coopStoreT(m, &staged[base], 16u);
    workgroupBarrier();
    for (var e = 0u; e < 8u; e++) {
        let v = lane + 32u * e;
        finish(row + v / 16u, col + v % 16u, staged[base + v]);
    }
}

