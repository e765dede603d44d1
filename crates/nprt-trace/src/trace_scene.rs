//! A scene made ready for tracing: its geometry under an acceleration structure, and the
//! per-material data integrated once (plastic coatings).

use std::ops::Deref;
use std::sync::Arc;

use glam::Vec2;
use nprt_scene::{Material, Scattering, Scene, Surface};
use rayon::prelude::*;

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
        let (accel, coatings) = rayon::join(|| Accel::new(&scene), || coatings(&scene));
        TraceScene {
            accel,
            scene,
            coatings,
        }
    }
}

/// Per material, the coat of a plastic (`None` for the others). A rough coat's tables take a
/// quadrature of about a million GGX samples: each distinct (eta, alpha) is integrated once, in
/// parallel (the KITCHEN's 22 rough plastics have 6; their tables took a third of its load).
fn coatings(scene: &Scene) -> Vec<Option<Coating>> {
    let key = |m: &Material| match (m.scattering, &m.surface) {
        (Scattering::Plastic { eta, rough, .. }, Surface::Direct { alpha, .. }) => {
            Some((eta.to_bits(), alpha.eval(Vec2::ZERO).x.to_bits(), rough))
        }
        _ => None,
    };
    let keys: Vec<_> = scene.materials.iter().map(key).collect();
    let mut distinct: Vec<_> = keys.iter().flatten().copied().collect();
    distinct.sort_unstable();
    distinct.dedup();
    let made: Vec<Coating> = distinct
        .par_iter()
        .map(|&(eta, alpha, rough)| Coating::new(f32::from_bits(eta), f32::from_bits(alpha), rough))
        .collect();
    keys.iter()
        .map(|k| k.map(|k| made[distinct.binary_search(&k).unwrap()].clone()))
        .collect()
}
