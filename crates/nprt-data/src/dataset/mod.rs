//! The dataset on disk (format documented in docs/dataset.md): `manifest.json` and one OpenEXR
//! per view under `views/`. The manifest is a pure function of the settings, so every shard
//! computes the same one; views are rendered by whichever shard owns them (index mod N), written
//! atomically, and skipped on resume once they read back complete.

mod generation;
mod manifest;
mod pack_format;
mod packed;
mod packed_pixel;
mod packed_transfer;
mod packing;
mod plan;
mod scene_identity;
mod transfer;
mod verify;
mod view_file;
mod view_parts;
mod view_spec;

pub use generation::{
    check_not_model_folder, prepare, render_view, run, Summary, MODEL_FOLDER_ENTRIES,
};
pub use manifest::{
    check_bounds, load_manifest, load_manifest_hashed, Jitter, Manifest, MapRecord, MixTerm,
    Settings, ViewRecord, VolumeRecord, FORMAT_VERSION, MANIFEST,
};
pub use pack_format::{PackHeader, PackedTarget, PACK_FORMAT, PACK_VERSION};
pub use packed::PackedDataset;
pub use packed_pixel::{PackedPixel, PACKED_PIXEL_BYTES};
pub use packed_transfer::{PackedTransfer, TransferSection};
pub use packing::views_stamp;
pub use plan::{plan, MapAssignment, Request, MAX_MIX_MAPS};
pub use scene_identity::{load_checked_scene, relit, scene_hash, scene_source};
pub use transfer::{Transfer, TransferBasis, MAX_TRANSFER_BAND};
pub use verify::{verify, Report};
pub use view_file::{check_view, read_view, write_view, ViewImage};
pub use view_parts::ViewParts;
pub use view_spec::ViewSpec;
