// The parameters of a U-Net decoder level's join (upsample_concat) and of its adjoint
// (upsample_backward): `x`, c_x channels of h × w per view, up-sampled ×2 and followed by the
// level's skip, c_skip channels of 2h × 2w.
struct Upsample {
    c_x: u32,
    c_skip: u32,
    h: u32,
    w: u32,
    views: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

