//! A folder of PNG frames as an animation: MP4 through ffmpeg when it is on PATH, otherwise an
//! animated GIF.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{Context, Result};
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbaImage};
use nprt_io::write_atomically;

/// Which animation was written.
pub enum Animation {
    Mp4(PathBuf),
    Gif(PathBuf),
}

impl Animation {
    pub fn path(&self) -> &Path {
        match self {
            Animation::Mp4(p) | Animation::Gif(p) => p,
        }
    }
}

/// Encodes the PNG frames `frames` (in order) as `stem.mp4` with ffmpeg when it runs, else as
/// `stem.gif`.
pub fn write_animation(frames: &[PathBuf], fps: u32, stem: &Path) -> Result<Animation> {
    let mp4 = stem.with_extension("mp4");
    if let Some(dir) = frames.first().and_then(|f| f.parent()) {
        let list = dir.join("ffmpeg-frames.txt");
        let body: String = frames
            .iter()
            .map(|f| {
                format!(
                    "file '{}'\nduration {}\n",
                    f.file_name().unwrap().to_string_lossy(),
                    1.0 / fps as f64
                )
            })
            .collect();
        std::fs::write(&list, body)
            .with_context(|| format!("cannot write '{}'", list.display()))?;
        let ok = Command::new("ffmpeg")
            .args([
                "-y",
                "-loglevel",
                "error",
                "-f",
                "concat",
                "-safe",
                "0",
                "-i",
            ])
            .arg(&list)
            .args([
                "-r",
                &fps.to_string(),
                "-pix_fmt",
                "yuv420p",
                "-vf",
                "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            ])
            .arg(&mp4)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        std::fs::remove_file(&list).ok();
        if ok {
            return Ok(Animation::Mp4(mp4));
        }
    }
    let gif = stem.with_extension("gif");
    write_atomically(&gif, |tmp| {
        let file = std::fs::File::create(tmp)?;
        let mut enc = GifEncoder::new_with_speed(std::io::BufWriter::new(file), 10);
        enc.set_repeat(Repeat::Infinite)?;
        for f in frames {
            let img: RgbaImage = image::open(f)
                .with_context(|| format!("cannot read frame '{}'", f.display()))?
                .to_rgba8();
            enc.encode_frame(Frame::from_parts(
                img,
                0,
                0,
                Delay::from_numer_denom_ms(1000, fps),
            ))?;
        }
        Ok(())
    })?;
    Ok(Animation::Gif(gif))
}
