//! What the viewer's keys do, typed or scripted (`--keys`).

use anyhow::Result;
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{Key, NamedKey, SmolStr};

use super::viewer_state::Viewer;
use crate::relight::FrameCache;
use crate::{Precision, ScriptedKey};

impl Viewer<'_> {
    /// Keys that leave the view as it is: the run's, the comparison's, screenshots and the
    /// overlay. Returns whether `key` was one.
    pub(super) fn key_in_place(&mut self, key: &Key) -> Result<bool> {
        let c = match key {
            Key::Named(NamedKey::Space) => " ".to_string(),
            Key::Named(NamedKey::F12) => "p".to_string(),
            Key::Character(c) => c.to_lowercase(),
            _ => return Ok(false),
        };
        match (c.as_str(), &mut self.training) {
            (" ", Some(t)) => {
                t.toggle_pause();
            }
            // An ended run was saved at its end; only a running one has a step to save at.
            ("k", Some(_)) if self.said.ended => {
                self.message = "the run has ended and is saved (X trains it longer)".into();
            }
            ("k", Some(t)) => {
                t.save();
                self.message = "saving …".into();
            }
            ("x", Some(t)) => {
                t.extend(self.opts.extend_minutes)?;
                self.said.ended = false;
                self.message = format!("the run now lasts {} minutes", t.minutes());
            }
            ("v", _) => {
                self.compare = self.compare.next();
                self.l1 = None;
                self.shown = None; // composed another way
            }
            ("[", _) => self.move_divider(self.divider - 0.05),
            ("]", _) => self.move_divider(self.divider + 0.05),
            ("p", _) => self.take_screenshot()?,
            ("h", _) => self.overlay = !self.overlay,
            _ => return Ok(false),
        }
        Ok(true)
    }

    /// Puts the split view's divider at `at` of the width; the frame is composed again.
    pub(super) fn move_divider(&mut self, at: f32) {
        self.divider = at.clamp(0.0, 1.0);
        self.shown = None;
    }

    pub(super) fn key(&mut self, key: &Key, el: &ActiveEventLoop) -> Result<()> {
        if self.key_in_place(key)? {
            return Ok(());
        }
        if self.models.is_empty() && !matches!(key, Key::Named(NamedKey::Escape)) {
            return Ok(()); // no model yet to change
        }
        match key {
            Key::Named(NamedKey::Escape) => el.exit(),
            Key::Named(NamedKey::Tab) => {
                self.model = (self.model + 1) % self.models.len();
                self.cache = FrameCache::default();
            }
            Key::Character(c) => match c.to_lowercase().as_str() {
                "m" => self.map = (self.map + 1) % self.maps.len(),
                "r" => self.show_reference = !self.show_reference,
                "f" => {
                    // f16 ⇄ f32 on the GPU kernels; a model on the CPU stays f32.
                    let model = &mut self.models[self.model];
                    let other = match model.precision() {
                        Precision::F32 => Precision::F16,
                        Precision::F16 => Precision::F32,
                    };
                    if model.set_precision(other).is_ok() {
                        self.cache = FrameCache::default();
                    }
                }
                "o" => {
                    // The next frame is made again: a denoised one takes the host's path.
                    self.denoise = !self.denoise && self.oidn.is_some();
                    self.cache = FrameCache::default();
                }
                "+" | "=" => self.exposure += 0.5,
                "-" => self.exposure -= 0.5,
                "w" => self.camera.fly(1.0, 0.0, 0.0),
                "s" => self.camera.fly(-1.0, 0.0, 0.0),
                "d" => self.camera.fly(0.0, 1.0, 0.0),
                "a" => self.camera.fly(0.0, -1.0, 0.0),
                "e" => self.camera.fly(0.0, 0.0, 1.0),
                "q" => self.camera.fly(0.0, 0.0, -1.0),
                _ => return Ok(()),
            },
            _ => return Ok(()),
        }
        self.moved();
        Ok(())
    }

    pub(super) fn take_screenshot(&mut self) -> Result<()> {
        let path = (0..)
            .map(|i| {
                self.opts
                    .screenshot_dir
                    .join(format!("nprt-view-{i:04}.png"))
            })
            .find(|p| !p.exists())
            .expect("a free name");
        self.screenshot(&path)?;
        self.message = format!("wrote {}", path.display());
        if let Some(l1) = self.l1 {
            let spp = self.reference.spp;
            self.message += &format!(" (L1 {l1:.5} against the reference at {spp} spp)");
        }
        println!("{}", self.message);
        Ok(())
    }
}

/// The key a script presses, as the window would send it.
pub(super) fn scripted_key(key: ScriptedKey) -> Key {
    match key {
        ScriptedKey::Space => Key::Named(NamedKey::Space),
        ScriptedKey::Tab => Key::Named(NamedKey::Tab),
        ScriptedKey::Escape => Key::Named(NamedKey::Escape),
        ScriptedKey::F12 => Key::Named(NamedKey::F12),
        ScriptedKey::Character(c) => Key::Character(SmolStr::new(c.to_string())),
    }
}
