// One value's training loss and its slope in the prediction q (reference r), as nprt-net's
// Loss::element: log-L1, |log(1 + q) − log(1 + r)| (loss 0, continued below q = 0 by its
// tangent), or relative L2, (q − r)² / (q² + ε) with q held constant in the weight (loss 1).
// Returns (value, slope).

const RELATIVE_L2_EPS: f32 = 0.01;

fn loss_element(loss: u32, q: f32, r: f32) -> vec2<f32> {
    if (loss == 0u) {
        // Below 0 log(1 + q) goes on as its tangent there, q itself (Loss::element): a linear
        // track's dot product can be negative while it learns.
        var lq = q;
        var slope = 1.0;
        if (q >= 0.0) {
            lq = log(1.0 + q);
            slope = 1.0 / (1.0 + q);
        }
        let d = lq - log(1.0 + r);
        return vec2<f32>(abs(d), sign(d) * slope);
    }
    let d = q - r;
    let w = 1.0 / (q * q + RELATIVE_L2_EPS);
    return vec2<f32>(d * d * w, 2.0 * d * w);
}
