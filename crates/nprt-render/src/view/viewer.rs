//! The viewer's state and event loop: what the mouse and keys change, and which parts of the
//! frame a change makes again (a lighting change under a still camera reruns the encoder and
//! the shading networks only).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use glam::Vec3;
use nprt_net::Engine;
use nprt_scene::{EnvMap, Scene};
use nprt_trace::{PixelFilter, RenderSettings, TraceScene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

use super::orbit_camera::OrbitCamera;
use super::overlay::draw_lines;
use super::presenter::{Presenter, Shown, OVERLAY_ROWS};
use crate::frame_stages::FrameRadiance;
use crate::frame_timings::FrameTimings;
use crate::oidn::Oidn;
use crate::relight::{DirectSampling, FrameCache, Relighter};
use crate::CameraPath;
use crate::Denoise;
use crate::Precision;

/// What `nprt view` shows and how.
pub struct ViewerOptions {
    /// Model folders of one scene; Tab switches among them.
    pub models: Vec<PathBuf>,
    /// The scene (default: the first model's).
    pub scene: Option<String>,
    /// A camera volume's JSON file to start the camera in (default: the scene's sidecar).
    pub camera_volume: Option<PathBuf>,
    /// Lightings (map files or built-in specs); M switches among them.
    pub maps: Vec<String>,
    pub resolution: [u32; 2],
    /// Where the networks run.
    pub engine: Engine,
    /// Samples per pixel of traced direct light, for models that trace it.
    pub direct_spp: u32,
    /// Whether that light is denoised (O toggles it where OIDN is installed).
    pub denoise_direct: Denoise,
    /// Exposure in stops.
    pub exposure: f32,
    /// Degrees the map turns each frame (0: still until moved).
    pub spin_deg: f32,
    /// Folder of the screenshots the P key takes.
    pub screenshot_dir: PathBuf,
    /// Close after this many frames, writing `screenshot` of the last (scripts and tests).
    pub frames: Option<usize>,
    pub screenshot: Option<PathBuf>,
    /// Start in path-tracing mode (the R key).
    pub reference: bool,
    /// Start with the overlay hidden (the H key).
    pub hide_overlay: bool,
    /// The networks' arithmetic.
    pub precision: Precision,
}

/// Opens the window and runs until it is closed (or `frames` are drawn).
pub fn run_viewer(opts: ViewerOptions) -> Result<()> {
    let (models, scene) = load(&opts)?;
    let mut viewer = Viewer::new(opts, models, &scene)?;
    let event_loop = EventLoop::new().map_err(|e| {
        anyhow!("nprt view needs a display ({e}); on a machine without one, run it under Xvfb (scripts/xvfb.sh installs it)")
    })?;
    event_loop
        .run_app(&mut viewer)
        .context("the window's event loop")?;
    match viewer.failed.take() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Progressive path tracing of the current view: the running sum and its samples per pixel.
struct Reference {
    sum: Vec<Vec3>,
    spp: u32,
    pass_ms: f64,
}

struct Viewer<'a> {
    opts: ViewerOptions,
    scene: &'a Scene,
    ts: TraceScene<'a>,
    models: Vec<Relighter>,
    maps: Vec<(String, EnvMap)>,
    camera: OrbitCamera,
    model: usize,
    map: usize,
    rotation: f32,
    exposure: f32,
    reference: Option<Reference>,
    /// The denoiser of traced direct light, where one is installed and asked for, and whether
    /// it is on (the O key).
    oidn: Option<&'static Oidn>,
    denoise: bool,
    /// What the current model kept of the last frame: its camera's G-buffer and network
    /// inputs, and the code of its lighting (map and rotation).
    cache: FrameCache<(usize, u32)>,
    timings: FrameTimings,
    frames: usize,
    fps: f64,
    last_frame: Option<Instant>,
    drag: Option<(MouseButton, f64, f64)>,
    cursor: (f64, f64),
    /// The last frame drawn and its overlay (RGBA8 over the frame's top rows; empty when
    /// hidden), for screenshots.
    shown: Option<FrameRadiance>,
    overlay_rgba: Vec<u8>,
    overlay: bool,
    message: String,
    window: Option<Arc<Window>>,
    presenter: Option<Presenter>,
    failed: Option<anyhow::Error>,
}

/// The models and their scene, checked to be one scene.
fn load(opts: &ViewerOptions) -> Result<(Vec<Relighter>, Scene)> {
    if opts.models.is_empty() {
        bail!("nprt view: give at least one model folder");
    }
    if opts.maps.is_empty() {
        bail!("nprt view: give at least one map");
    }
    let [w, h] = opts.resolution;
    opts.engine
        .tracer()
        .check_frame(w, h, &format!("a {w}×{h} window"))?;
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

impl<'a> Viewer<'a> {
    fn new(opts: ViewerOptions, models: Vec<Relighter>, scene: &'a Scene) -> Result<Self> {
        let spec = opts
            .scene
            .clone()
            .unwrap_or_else(|| models[0].file.scene.clone());
        let path = CameraPath::through_volume_of(
            opts.camera_volume.as_deref(),
            scene,
            &spec,
            "give --camera-volume to start the camera in",
        )?;
        let k = &path.keyframes[0];
        let camera = OrbitCamera::new(k.position.into(), k.target.into(), k.fov_x_deg);
        let maps = opts
            .maps
            .iter()
            .map(|m| Ok((m.clone(), nprt_scene::open_envmap(m)?)))
            .collect::<Result<Vec<_>>>()?;
        let reference = opts.reference.then(|| Reference {
            sum: Vec::new(),
            spp: 0,
            pass_ms: 0.0,
        });
        // Resolved for every model, so that `on` without OIDN, or for a model that traces no
        // light, is refused before the window opens.
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
            reference,
            denoise: oidn.is_some(),
            oidn,
            cache: FrameCache::default(),
            timings: FrameTimings::default(),
            frames: 0,
            fps: 0.0,
            last_frame: None,
            drag: None,
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
    /// kernels made it there), or the reference's running mean.
    fn radiance(&mut self) -> Result<FrameRadiance> {
        let [w, h] = self.opts.resolution;
        let camera = self.camera.camera(w, h);
        let map = &self.maps[self.map].1;
        if let Some(r) = &mut self.reference {
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
            return Ok(FrameRadiance::Host(r.sum.iter().map(|s| *s * k).collect()));
        }
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
        Ok(shown)
    }

    /// What the overlay says.
    fn overlay(&self, adapter: &str) -> Vec<String> {
        let model = &self.models[self.model];
        let mut lines = vec![
            format!(
                "{} [{}/{}]  exposure {:+.1}",
                model.file.config.label(),
                self.model + 1,
                self.models.len(),
                self.exposure
            ),
            format!("{} at {:.0} deg", self.maps[self.map].0, self.rotation),
        ];
        match &self.reference {
            Some(r) => lines.push(format!(
                "path-traced reference {}: {} spp, {:.0} ms per pass",
                model.paths_on(),
                r.spp,
                r.pass_ms
            )),
            None => {
                let t = &self.timings;
                lines.push(format!(
                    "G-buffer {:.1}  encoder {:.1} ms",
                    t.gbuffer_ms, t.encoder_ms
                ));
                lines.push(format!(
                    "networks {:.1}  direct {:.1} ms",
                    t.network_ms, t.direct_ms
                ));
                lines.push(format!("total {:.1} ms", t.total_ms()));
                if model.traces_direct() {
                    let denoised = match (self.oidn, self.denoise) {
                        (None, _) => "not denoised (no OIDN)",
                        (Some(_), true) => "denoised by OIDN (O: off)",
                        (Some(_), false) => "not denoised (O: on)",
                    };
                    lines.push(format!(
                        "direct light {} spp, {denoised}",
                        self.opts.direct_spp
                    ));
                }
                lines.push(format!("networks on the {}", model.networks_on()));
                lines.push(format!("G-buffer {}", model.gbuffer_on()));
            }
        }
        lines.push(format!("{:.1} fps, shown by {adapter}", self.fps));
        lines.push("drag orbit, right-drag map, wheel dolly".into());
        lines.push("WASDQE fly, Tab model, M map, R reference, F f16, O denoise".into());
        lines.push("+/- exposure, P screenshot, H hide, Esc quit".into());
        if !self.message.is_empty() {
            lines.push(self.message.clone());
        }
        lines
    }

    fn redraw(&mut self) -> Result<()> {
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
        let [w, h] = self.opts.resolution;
        self.overlay_rgba.clear();
        if self.overlay {
            let adapter = &self.presenter.as_ref().expect("a window is open").adapter;
            let lines = self.overlay(adapter);
            let rows = h.min(OVERLAY_ROWS) as usize;
            self.overlay_rgba.resize(4 * w as usize * rows, 0);
            draw_lines(&mut self.overlay_rgba, w as usize, &lines, 1);
        }
        let shown = Shown {
            frame: &rgb,
            exposure: self.exposure,
            overlay: &self.overlay_rgba,
        };
        self.presenter.as_mut().expect("open").present(&shown)?;
        self.shown = Some(rgb);
        self.frames += 1;
        self.rotation = (self.rotation + self.opts.spin_deg).rem_euclid(360.0);
        Ok(())
    }

    /// Writes the frame on screen, overlay included, as a PNG.
    fn screenshot(&self, path: &std::path::Path) -> Result<()> {
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
    fn animating(&self) -> bool {
        self.opts.spin_deg != 0.0 || self.reference.is_some() || self.opts.frames.is_some()
    }

    /// The view changed: the reference starts again.
    fn moved(&mut self) {
        if let Some(r) = &mut self.reference {
            r.sum.clear();
            r.spp = 0;
        }
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }

    fn key(&mut self, key: &Key, el: &ActiveEventLoop) -> Result<()> {
        match key {
            Key::Named(NamedKey::Escape) => el.exit(),
            Key::Named(NamedKey::Tab) => {
                self.model = (self.model + 1) % self.models.len();
                self.cache = FrameCache::default();
            }
            Key::Named(NamedKey::F12) => self.take_screenshot()?,
            Key::Character(c) => match c.to_lowercase().as_str() {
                "m" => self.map = (self.map + 1) % self.maps.len(),
                "r" => {
                    self.reference = match self.reference {
                        Some(_) => None,
                        None => Some(Reference {
                            sum: Vec::new(),
                            spp: 0,
                            pass_ms: 0.0,
                        }),
                    }
                }
                "p" => self.take_screenshot()?,
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
                "h" => self.overlay = !self.overlay,
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

    fn take_screenshot(&mut self) -> Result<()> {
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
        println!("{}", self.message);
        Ok(())
    }

    fn handle(&mut self, el: &ActiveEventLoop, event: WindowEvent) -> Result<()> {
        match event {
            WindowEvent::CloseRequested => el.exit(),
            WindowEvent::Resized(size) => {
                if let Some(p) = &mut self.presenter {
                    p.resize(size.width, size.height);
                }
            }
            WindowEvent::RedrawRequested => {
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
                if self.animating() {
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

    fn window_event(&mut self, el: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        if let Err(e) = self.handle(el, event) {
            self.failed = Some(e);
            el.exit();
        }
    }
}
