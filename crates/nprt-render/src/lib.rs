//! nprt-render: run-time Neural PRT. It owns turning a trained model plus a G-buffer and an
//! environment map into a globally illuminated frame, camera paths and lighting schedules over
//! time, and writing frames and animations. It reads models through nprt-net and traces only
//! primary rays (for the G-buffer) through nprt-trace; it must not train networks, write
//! datasets or compute error metrics.

pub mod path;
pub mod relight;
pub mod schedule;
pub mod sequence;
pub mod video;

pub use path::CameraPath;
pub use relight::{background, FrameTimings, LightCode, Relighter};
pub use schedule::LightingSchedule;
pub use sequence::{render_sequence, FrameReport, Sequence, SequenceSummary};
pub use video::{srgb8, write_animation, write_png, Animation};
