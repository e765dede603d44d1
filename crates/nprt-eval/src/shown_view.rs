//! A test view's images as the report shows them.

use glam::Vec3;
use nprt_data::views::ImageView;

/// A test view's images for the report.
#[derive(Clone, Debug)]
pub struct ShownView {
    pub index: usize,
    pub width: usize,
    pub height: usize,
    pub mask: Vec<f32>,
    pub reference: Vec<Vec3>,
    /// (method name, radiance).
    pub methods: Vec<(String, Vec<Vec3>)>,
}

impl ShownView {
    /// A test view with its reference, before any method's image is added.
    pub fn of(v: &ImageView) -> Self {
        ShownView {
            index: v.record.index as usize,
            width: v.width,
            height: v.height,
            mask: v.gbuffer.mask.clone(),
            reference: v.radiance.clone(),
            methods: vec![],
        }
    }
}
