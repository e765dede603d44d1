//! The viewer's state and event loop: what the mouse and keys change, and which parts of the
//! frame a change makes again (a lighting change under a still camera reruns the encoder and
//! the shading networks only).

use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use nprt_scene::Scene;
use nprt_trace::{PixelFilter, RenderSettings, TraceScene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, StartCause, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

use super::compare::{compose, l1, Compare, ERROR_SPP};
use super::live_training::Training;
use super::orbit_camera::OrbitCamera;
use super::presenter::{Presenter, Shown};
use super::viewer_keys::scripted_key;
use super::viewer_state::{Reference, Said, Viewer, ViewerOptions};
use super::viewer_training::{dataset_maps, finish_training};
use crate::frame_stages::DirectSampling;
use crate::frame_stages::FrameRadiance;
use crate::frame_timings::FrameTimings;
use crate::oidn::Oidn;
use crate::relight::{FrameCache, Relighter};
use crate::CameraPath;
use crate::Denoise;

/// Opens the window and runs until it is closed (or `frames` are drawn).
pub fn run_viewer(mut opts: ViewerOptions) -> Result<()> {
    let training = opts.training.take().map(Training::start).transpose()?;
    let (models, scene) = load(&opts, training.as_ref())?;
    let mut viewer = Viewer::new(opts, models, &scene, training)?;
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!("nprt view needs a display ({e}); on a machine without one, run it under Xvfb (scripts/xvfb.sh installs it)")
    });
    let shown = event_loop.and_then(|l| l.run_app(&mut viewer).context("the window's event loop"));
    if let Some(opened) = viewer.opened {
        let seconds = opened.elapsed().as_secs_f64();
        let n = viewer.frames;
        println!(
            "nprt view: {n} frames in {seconds:.1} s ({:.1} a second)",
            n as f64 / seconds.max(1e-9)
        );
    }
    // The run is saved, however the window ended.
    let trained = viewer.training.take().map(finish_training).transpose();
    shown?;
    trained?;
    match viewer.failed.take() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// The models and their scene, checked to be one scene (a run's: its dataset's).
fn load(opts: &ViewerOptions, training: Option<&Training>) -> Result<(Vec<Relighter>, Scene)> {
    let [w, h] = opts.resolution;
    opts.engine
        .tracer()
        .check_frame(w, h, &format!("a {w}×{h} window"))?;
    if let Some(t) = training {
        let s = &t.manifest.settings;
        let spec = opts.scene.as_deref().unwrap_or(&s.scene);
        let what = "the dataset was made of";
        return Ok((
            Vec::new(),
            nprt_data::dataset::load_checked_scene(spec, &s.scene_hash, what)?,
        ));
    }
    if opts.models.is_empty() {
        bail!("nprt view: give at least one model folder, or --train DATA");
    }
    if opts.maps.is_empty() {
        bail!("nprt view: give at least one map");
    }
    let models = opts
        .models
        .iter()
        .map(|m| {
            let mut model = Relighter::load(m, opts.engine)?;
            model.set_precision(opts.precision)?;
            Ok(model)
        })
        .collect::<Result<Vec<_>>>()?;
    let first = &models[0].file;
    let spec = match (&opts.scene, first.scene.as_str()) {
        (Some(s), _) => s.clone(),
        (None, "") => bail!(
            "model '{}' does not record its scene; give --scene",
            opts.models[0].display()
        ),
        (None, s) => s.to_string(),
    };
    for (m, path) in models.iter().zip(&opts.models) {
        if m.file.scene_hash != first.scene_hash {
            bail!(
                "model '{}' was trained on another scene than '{}'",
                path.display(),
                opts.models[0].display()
            );
        }
    }
    let scene = nprt_data::dataset::load_checked_scene(
        &spec,
        &first.scene_hash,
        &format!("model '{}' was trained on", opts.models[0].display()),
    )?;
    Ok((models, scene))
}

/// The denoiser of the traced direct light `opts` asks for, resolved for every model, so that
/// `on` without OIDN, or for a model that traces no light, is refused before the window opens;
/// each model is described as it will be shown.
fn denoiser(opts: &ViewerOptions, models: &[Relighter]) -> Result<Option<&'static Oidn>> {
    let mut oidn = None;
    for (m, dir) in models.iter().zip(&opts.models) {
        oidn = oidn.or(opts.denoise_direct.denoiser(m, dir)?);
    }
    if opts.denoise_direct == Denoise::Auto && oidn.is_none() {
        oidn = Oidn::open().ok();
    }
    for (m, dir) in models.iter().zip(&opts.models) {
        let sampling = DirectSampling {
            spp: opts.direct_spp,
            seed: 0,
            denoiser: oidn.filter(|_| m.traces_direct()),
        };
        println!("nprt view: '{}': {}", dir.display(), m.describe(&sampling));
    }
    Ok(oidn)
}

impl<'a> Viewer<'a> {
    pub(super) fn new(
        opts: ViewerOptions,
        models: Vec<Relighter>,
        scene: &'a Scene,
        training: Option<Training>,
    ) -> Result<Self> {
        let path = match (&training, &opts.camera_volume) {
            (Some(t), None) => {
                CameraPath::through_volume(&t.manifest.settings.camera_volume.volume())
            }
            _ => {
                let spec = (opts.scene.clone()).unwrap_or_else(|| models[0].file.scene.clone());
                let hint = "give --camera-volume to start the camera in";
                CameraPath::through_volume_of(opts.camera_volume.as_deref(), scene, &spec, hint)?
            }
        };
        let k = &path.keyframes[0];
        let camera = OrbitCamera::new(k.position.into(), k.target.into(), k.fov_x_deg);
        let maps = match &training {
            Some(t) if opts.maps.is_empty() => dataset_maps(&t.manifest)?,
            _ => (opts.maps.iter())
                .map(|m| Ok((m.clone(), nprt_scene::open_envmap(m)?)))
                .collect::<Result<Vec<_>>>()?,
        };
        let oidn = denoiser(&opts, &models)?;
        Ok(Viewer {
            ts: TraceScene::new(scene),
            scene,
            models,
            maps,
            camera,
            model: 0,
            map: 0,
            rotation: 0.0,
            exposure: opts.exposure,
            reference: Reference::default(),
            show_reference: opts.reference,
            compare: Compare::Off,
            divider: 0.5,
            l1: None,
            stale: true,
            model_rgb: None,
            worked: None,
            training,
            said: Said::default(),
            keys: {
                let mut keys = opts.keys.clone();
                keys.sort_by(|a, b| a.0.total_cmp(&b.0));
                keys.into()
            },
            opened: None,
            denoise: oidn.is_some(),
            oidn,
            cache: FrameCache::default(),
            timings: FrameTimings::default(),
            frames: 0,
            fps: 0.0,
            last_frame: None,
            drag: None,
            on_divider: false,
            cursor: (0.0, 0.0),
            shown: None,
            overlay_rgba: Vec::new(),
            overlay: !opts.hide_overlay,
            message: String::new(),
            window: None,
            presenter: None,
            failed: None,
            opts,
        })
    }

    /// The frame's linear radiance: the model's relighting (left on the device where the GPU
    /// kernels made it there), the reference's running mean, or the two compared.
    pub(super) fn radiance(&mut self) -> Result<FrameRadiance> {
        let paced = self.pacing();
        if !paced {
            self.take_newest_model()?;
        }
        self.say_training();
        let [w, h] = self.opts.resolution;
        if self.models.is_empty() {
            return Ok(FrameRadiance::Host(vec![Vec3::ZERO; (w * h) as usize]));
        }
        let still = !std::mem::replace(&mut self.stale, false);
        if still && paced {
            if let Some(shown) = self.shown.take() {
                return Ok(shown);
            }
        }
        let clock = Instant::now();
        let shown = self.made(still)?;
        self.worked = Some((Instant::now(), clock.elapsed().as_secs_f64()));
        Ok(shown)
    }

    /// [`Self::radiance`] made: the reference's next pass, or the model's frame (made again
    /// unless the view is `still`) alone or compared.
    fn made(&mut self, still: bool) -> Result<FrameRadiance> {
        let [w, h] = self.opts.resolution;
        if self.show_reference {
            return Ok(FrameRadiance::Host(self.reference_pass()?));
        }
        // A still view's model frame is kept: as shown, or as compared last.
        match (still, self.compare) {
            (true, Compare::Off) => {
                if let Some(shown) = self.shown.take() {
                    return Ok(shown);
                }
                if let Some(model) = self.model_rgb.take() {
                    return Ok(FrameRadiance::Host(model));
                }
            }
            (true, _) => {
                if let Some(model) = self.model_rgb.take() {
                    return self.compared(model);
                }
            }
            (false, _) => self.model_rgb = None,
        }
        let camera = self.camera.camera(w, h);
        let map = &self.maps[self.map].1;
        let sampling = DirectSampling {
            spp: self.opts.direct_spp,
            seed: self.frames as u64,
            denoiser: self.oidn.filter(|_| self.denoise),
        };
        let key = (self.map, self.rotation.to_bits());
        let lit = (map, self.rotation, key);
        let model = &self.models[self.model];
        let (shown, t) =
            model.frame_shown(&mut self.cache, &self.ts, &camera, lit, sampling, true)?;
        self.timings = t;
        if self.compare == Compare::Off {
            self.l1 = None;
            return Ok(shown);
        }
        self.compared(shown.into_host())
    }

    /// The model's frame `model` compared with the reference, one more sample into it.
    pub(super) fn compared(&mut self, model: Vec<Vec3>) -> Result<FrameRadiance> {
        let w = self.opts.resolution[0];
        let reference = self.reference_pass()?;
        self.l1 = Some(l1(&model, &reference));
        // The error of a reference this noisy would mostly be its noise: the split until then.
        let mode = match self.compare {
            Compare::Error if self.reference.spp < ERROR_SPP => Compare::Split,
            mode => mode,
        };
        let (width, divider, exposure) = (w as usize, self.divider, self.exposure);
        let composed = compose(mode, &model, &reference, width, divider, exposure);
        self.model_rgb = Some(model);
        Ok(FrameRadiance::Host(composed))
    }

    /// One more path-traced sample per pixel of the view; the reference's running mean.
    pub(super) fn reference_pass(&mut self) -> Result<Vec<Vec3>> {
        let [w, h] = self.opts.resolution;
        let camera = self.camera.camera(w, h);
        let map = &self.maps[self.map].1;
        let r = &mut self.reference;
        let clock = Instant::now();
        let pass = self.models[self.model].path_trace(
            &self.ts,
            &camera,
            &map.rotated_y(self.rotation),
            &RenderSettings {
                spp: 1,
                max_depth: self.scene.max_depth,
                rr_depth: self.scene.rr_depth,
                seed: r.spp as u64,
                filter: PixelFilter::Box,
                progress: false,
            },
        )?;
        r.pass_ms = clock.elapsed().as_secs_f64() * 1e3;
        if r.sum.len() != pass.len() {
            r.sum = vec![Vec3::ZERO; pass.len()];
        }
        r.sum.iter_mut().zip(&pass).for_each(|(s, p)| *s += *p);
        r.spp += 1;
        let k = 1.0 / r.spp as f32;
        Ok(r.sum.iter().map(|s| *s * k).collect())
    }

    pub(super) fn redraw(&mut self) -> Result<()> {
        let rgb = self.radiance()?;
        let now = Instant::now();
        if let Some(last) = self.last_frame {
            let fps = 1.0 / now.duration_since(last).as_secs_f64().max(1e-6);
            self.fps = if self.fps == 0.0 {
                fps
            } else {
                0.8 * self.fps + 0.2 * fps
            };
        }
        self.last_frame = Some(now);
        self.overlay_rgba.clear();
        if self.overlay {
            self.draw_overlay();
        }
        let shown = Shown {
            frame: &rgb,
            exposure: self.exposure,
            overlay: &self.overlay_rgba,
        };
        self.presenter.as_mut().expect("open").present(&shown)?;
        self.shown = Some(rgb);
        self.frames += 1;
        if self.opts.spin_deg != 0.0 {
            self.rotation = (self.rotation + self.opts.spin_deg).rem_euclid(360.0);
            self.moved();
        }
        Ok(())
    }

    /// Writes the frame on screen, overlay included, as a PNG.
    pub(super) fn screenshot(&self, path: &std::path::Path) -> Result<()> {
        let [w, h] = self.opts.resolution;
        let frame = self.shown.as_ref().context("no frame drawn yet")?;
        let shown = Shown {
            frame,
            exposure: self.exposure,
            overlay: &self.overlay_rgba,
        };
        let rgba = self.presenter.as_ref().expect("open").screenshot(&shown);
        let image =
            image::RgbaImage::from_raw(w, h, rgba).context("a screenshot of the frame's size")?;
        nprt_io::write_atomically(path, |tmp| {
            image
                .save_with_format(tmp, image::ImageFormat::Png)
                .with_context(|| format!("cannot write {}", tmp.display()))
        })
    }

    /// Whether frames keep coming without input: a spinning map or a reference converging.
    pub(super) fn animating(&self) -> bool {
        self.opts.spin_deg != 0.0
            || self.show_reference
            || self.compare != Compare::Off
            || self.training.is_some()
            || self.opts.frames.is_some()
    }

    /// Whether the next frame only shows the last again, with the run's figures.
    pub(super) fn idling(&self) -> bool {
        let still = !self.show_reference && self.compare == Compare::Off;
        self.training.is_some()
            && !self.stale
            && (still || self.pacing())
            && self.opts.frames.is_none()
    }

    /// The view changed: the reference starts again.
    pub(super) fn moved(&mut self) {
        self.reference = Reference::default();
        self.stale = true;
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }

    pub(super) fn handle(&mut self, el: &ActiveEventLoop, event: WindowEvent) -> Result<()> {
        match event {
            WindowEvent::CloseRequested => el.exit(),
            WindowEvent::Resized(size) => {
                if let Some(p) = &mut self.presenter {
                    p.resize(size.width, size.height);
                }
            }
            WindowEvent::RedrawRequested => {
                let opened = *self.opened.get_or_insert_with(Instant::now);
                let now = opened.elapsed().as_secs_f64();
                while self.keys.front().is_some_and(|(t, _)| *t <= now) {
                    let (_, key) = self.keys.pop_front().expect("a key");
                    self.key(&scripted_key(key), el)?;
                }
                self.redraw()?;
                if let Some(n) = self.opts.frames {
                    if self.frames >= n {
                        if let Some(path) = &self.opts.screenshot {
                            self.screenshot(path)?;
                            println!("wrote {}", path.display());
                        }
                        el.exit();
                        return Ok(());
                    }
                }
                if self.idling() {
                    // Only the run's figures change: redrawn about seven times a second, so that the
                    // window leaves the cores to the training.
                    let next = Instant::now() + std::time::Duration::from_millis(150);
                    el.set_control_flow(ControlFlow::WaitUntil(next));
                } else if self.animating() {
                    el.set_control_flow(ControlFlow::Wait);
                    self.window.as_ref().expect("open").request_redraw();
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                self.key(&event.logical_key, el)?;
            }
            WindowEvent::MouseInput { state, button, .. } => {
                self.drag = (state == ElementState::Pressed).then_some((
                    button,
                    self.cursor.0,
                    self.cursor.1,
                ));
                let column = self.divider as f64 * self.opts.resolution[0] as f64;
                self.on_divider = self.compare != Compare::Off
                    && button == MouseButton::Left
                    && (self.cursor.0 - column).abs() <= 6.0;
            }
            WindowEvent::CursorMoved { position, .. } if self.drag.is_some() && self.on_divider => {
                self.cursor = (position.x, position.y);
                let width = self.opts.resolution[0] as f64;
                self.move_divider((position.x / width) as f32);
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((button, x, y)) = self.drag {
                    let (dx, dy) = ((position.x - x) as f32, (position.y - y) as f32);
                    match button {
                        MouseButton::Left => self.camera.orbit(dx, dy),
                        _ => self.rotation = (self.rotation + 0.5 * dx).rem_euclid(360.0),
                    }
                    self.drag = Some((button, position.x, position.y));
                    self.moved();
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.camera.dolly(0.9f32.powf(lines));
                self.moved();
            }
            _ => {}
        }
        Ok(())
    }
}

impl ApplicationHandler for Viewer<'_> {
    fn resumed(&mut self, el: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        let [w, h] = self.opts.resolution;
        let attributes = Window::default_attributes()
            .with_title("nprt view")
            .with_inner_size(PhysicalSize::new(w, h))
            .with_resizable(false);
        let opened = el
            .create_window(attributes)
            .map_err(|e| anyhow!("cannot open a window: {e}"))
            .and_then(|window| {
                let window = Arc::new(window);
                let presenter = Presenter::new(window.clone(), w, h)?;
                Ok((window, presenter))
            });
        match opened {
            Ok((window, presenter)) => {
                window.request_redraw();
                self.window = Some(window);
                self.presenter = Some(presenter);
            }
            Err(e) => {
                self.failed = Some(e);
                el.exit();
            }
        }
    }

    fn new_events(&mut self, _: &ActiveEventLoop, cause: StartCause) {
        if let (StartCause::ResumeTimeReached { .. }, Some(w)) = (cause, &self.window) {
            w.request_redraw();
        }
    }

    fn window_event(&mut self, el: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        if let Err(e) = self.handle(el, event) {
            self.failed = Some(e);
            el.exit();
        }
    }
}
