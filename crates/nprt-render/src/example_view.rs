//! The view `nprt export`'s worked example relights (a WebGPU page): its size and its map,
//! with the defaults the command line and Python both take.

/// The worked example's view: the model's scene from the start of `nprt render`'s default
/// camera path, at this size, under this lighting.
pub struct ExampleView {
    pub width: u32,
    pub height: u32,
    pub map: String,
}

impl Default for ExampleView {
    /// A 160 × 120 view under a late-afternoon sky: small enough for any browser's first frame.
    fn default() -> Self {
        ExampleView {
            width: 160,
            height: 120,
            map: "builtin:sky:30:250:3".into(),
        }
    }
}
