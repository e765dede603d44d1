//! A scene made ready for tracing: its geometry under an acceleration structure, and the
//! per-material data integrated once (plastic coatings).

use std::ops::Deref;
use std::sync::Arc;

use glam::Vec2;
use nprt_scene::{Scattering, Scene, Surface};

use crate::accel::Accel;
use crate::coating::Coating;

/// The scene a [`TraceScene`] traces: borrowed (a command's scene for its run), or shared,
/// for one kept as long as its holder (the Python package's scenes, traced call after call
/// without rebuilding the acceleration structure).
pub enum SceneRef<'a> {
    Borrowed(&'a Scene),
    Shared(Arc<Scene>),
}

impl Deref for SceneRef<'_> {
    type Target = Scene;

    fn deref(&self) -> &Scene {
        match self {
            SceneRef::Borrowed(s) => s,
            SceneRef::Shared(s) => s,
        }
    }
}

/// A scene ready for tracing: its geometry with an acceleration structure.
pub struct TraceScene<'a> {
    pub scene: SceneRef<'a>,
    pub accel: Accel,
    /// Per material: the coat of a plastic, integrated once here (`None` for the others).
    pub coatings: Vec<Option<Coating>>,
}

impl<'a> TraceScene<'a> {
    pub fn new(scene: &'a Scene) -> Self {
        Self::made(SceneRef::Borrowed(scene))
    }

    /// A scene ready for tracing that holds `scene` itself.
    pub fn shared(scene: Arc<Scene>) -> TraceScene<'static> {
        TraceScene::made(SceneRef::Shared(scene))
    }

    fn made(scene: SceneRef<'a>) -> Self {
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
            accel: Accel::new(&scene),
            scene,
            coatings,
        }
    }
}
