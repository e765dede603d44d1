//! Settings that change how a scene file is read.

/// Settings that change how a scene file is read.
#[derive(Clone, Debug, Default)]
pub struct SceneOptions {
    /// `NAME=VALUE` overrides of Mitsuba `<default>` parameters.
    pub set: Vec<(String, String)>,
    /// The caller lights the scene with maps of its own (`--envmap`, datasets, relighting):
    /// the scene's environment emitter is skipped, so a map file it names need not exist.
    pub lighting_replaced: bool,
}
