//! A scene made ready for tracing: its geometry under an acceleration structure, and the
//! per-material data integrated once (plastic coatings).

use glam::Vec2;
use nprt_scene::{Scattering, Scene, Surface};

use crate::accel::Accel;
use crate::coating::Coating;

/// A scene ready for tracing: its geometry with an acceleration structure.
pub struct TraceScene<'a> {
    pub scene: &'a Scene,
    pub accel: Accel,
    /// Per material: the coat of a plastic, integrated once here (`None` for the others).
    pub coatings: Vec<Option<Coating>>,
}

impl<'a> TraceScene<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        let coatings = scene
            .materials
            .iter()
            .map(|m| match (m.scattering, &m.surface) {
                (Scattering::Plastic { eta, rough, .. }, Surface::Direct { alpha, .. }) => {
                    Some(Coating::new(eta, alpha.eval(Vec2::ZERO).x, rough))
                }
                _ => None,
            })
            .collect();
        TraceScene {
            scene,
            accel: Accel::new(scene),
            coatings,
        }
    }
}
