//! Frames to files: tone-mapped PNG, and an animation through ffmpeg (MP4) when it is on PATH,
//! otherwise an animated GIF.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

use anyhow::{Context, Result};
use glam::Vec3;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, Frame, RgbImage, RgbaImage};
use nprt_io::write_atomically;
use nprt_scene::linear_to_srgb;

/// Linear radiance scaled by 2^exposure, clamped, sRGB-encoded.
pub fn srgb8(c: Vec3, exposure: f32) -> [u8; 3] {
    let scale = exposure.exp2();
    let encode = |c: f32| (linear_to_srgb(c * scale) * 255.0 + 0.5) as u8;
    [encode(c.x), encode(c.y), encode(c.z)]
}

pub fn to_image(rgb: &[Vec3], width: usize, height: usize, exposure: f32) -> RgbImage {
    RgbImage::from_fn(width as u32, height as u32, |x, y| {
        image::Rgb(srgb8(rgb[y as usize * width + x as usize], exposure))
    })
}

/// Writes a tone-mapped PNG atomically.
pub fn write_png(
    rgb: &[Vec3],
    width: usize,
    height: usize,
    exposure: f32,
    path: &Path,
) -> Result<()> {
    let img = to_image(rgb, width, height, exposure);
    write_atomically(path, |tmp| {
        Ok(img.save_with_format(tmp, image::ImageFormat::Png)?)
    })
}

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
