//! What the viewer's overlay says and draws: the frame's stages and what runs them, the run
//! trained beside the frames with its loss curves, the comparison with path tracing and its
//! error scale, and the keys.

use nprt_net::training::live::LiveStatus;

use super::compare::{Compare, ERROR_SPP};
use super::live_training::Training;
use super::overlay::{draw_curves, draw_lines, draw_scale, Area};
use super::presenter::OVERLAY_ROWS;
use super::viewer_state::Viewer;
use crate::relight::Relighter;

impl Viewer<'_> {
    /// What the overlay says (`status`: where the run trained beside the frames stands).
    pub(super) fn overlay(&self, adapter: &str, status: Option<&LiveStatus>) -> Vec<String> {
        let mut lines = Vec::new();
        if let (Some(t), Some(s)) = (&self.training, status) {
            lines.extend(training_lines(t, s, self.models.is_empty()));
        }
        let Some(model) = self.models.get(self.model) else {
            lines.push(format!("{:.1} fps, shown by {adapter}", self.fps));
            return lines;
        };
        lines.push(format!(
            "{} [{}/{}]  exposure {:+.1}",
            model.file.config.label(),
            self.model + 1,
            self.models.len(),
            self.exposure
        ));
        lines.push(format!(
            "{} at {:.0} deg",
            self.maps[self.map].0, self.rotation
        ));
        let r = &self.reference;
        if self.show_reference {
            lines.push(format!(
                "path-traced reference {}: {} spp, {:.0} ms per pass",
                model.paths_on(),
                r.spp,
                r.pass_ms
            ));
        } else {
            lines.extend(self.frame_lines(model));
        }
        if let Some(l1) = self.l1 {
            let shows = match self.compare {
                Compare::Error if r.spp >= ERROR_SPP => {
                    "error: relative L1 per pixel, 0 to 1 and over".into()
                }
                Compare::Error => format!("error shown from {ERROR_SPP} spp; until then split"),
                _ => "split: network | path traced ([ ] or drag the divider)".into(),
            };
            lines.push(shows);
            lines.push(format!("L1 {l1:.4} against the reference at {} spp", r.spp));
        }
        lines.push(format!("{:.1} fps, shown by {adapter}", self.fps));
        lines.push("drag orbit, right-drag map, wheel dolly".into());
        lines.push("WASDQE fly, Tab model, M map, R reference, F f16, O denoise".into());
        lines.push("V split/error, +/- exposure, P screenshot, H hide, Esc quit".into());
        if self.training.is_some() {
            let more = self.opts.extend_minutes;
            lines.push(format!(
                "Space pause/resume training, K save, X {more} minutes more"
            ));
        }
        if !self.message.is_empty() {
            lines.push(self.message.clone());
        }
        lines
    }

    /// The overlay's lines on the model's frame: its stages' times and what runs them.
    pub(super) fn frame_lines(&self, model: &Relighter) -> Vec<String> {
        let t = &self.timings;
        let mut lines = vec![
            format!(
                "G-buffer {:.1}  encoder {:.1} ms",
                t.gbuffer_ms, t.encoder_ms
            ),
            format!("networks {:.1}  direct {:.1} ms", t.network_ms, t.direct_ms),
            format!("total {:.1} ms", t.total_ms()),
        ];
        if model.traces_direct() {
            let denoised = match (self.oidn, self.denoise) {
                (None, _) => "not denoised (no OIDN)",
                (Some(_), true) => "denoised by OIDN (O: off)",
                (Some(_), false) => "not denoised (O: on)",
            };
            let spp = self.opts.direct_spp;
            lines.push(format!("direct light {spp} spp, {denoised}"));
        }
        lines.push(format!("networks on the {}", model.networks_on()));
        lines.push(format!("G-buffer {}", model.gbuffer_on()));
        lines
    }

    /// Draws the overlay: its lines, the run's loss curves below them, and the error's colour
    /// scale when the error is shown.
    pub(super) fn draw_overlay(&mut self) {
        let [w, h] = self.opts.resolution;
        let adapter = &self.presenter.as_ref().expect("a window is open").adapter;
        let status = self.training.as_ref().map(Training::status);
        let lines = self.overlay(adapter, status.as_ref());
        let rows = h.min(OVERLAY_ROWS) as usize;
        let width = w as usize;
        self.overlay_rgba.resize(4 * width * rows, 0);
        // The run's loss curves and the error's colour scale at the top right, the text
        // beside them.
        let side = width / 4;
        let area = |top: usize, height: usize| Area {
            left: width - side - 4,
            top,
            width: side,
            height,
        };
        let mut top = 4;
        if let Some(s) = &status {
            let (train, val) = loss_curves(&s.rows);
            let curves = [(&train[..], [220, 220, 220]), (&val[..], [255, 160, 40])];
            draw_curves(&mut self.overlay_rgba, width, area(top, side / 2), &curves);
            top += side / 2 + 4;
        }
        if self.compare == Compare::Error && self.reference.spp >= ERROR_SPP {
            draw_scale(
                &mut self.overlay_rgba,
                width,
                area(top, 6),
                super::compare::ramp,
            );
        }
        let text_width = match top {
            4 => width,
            _ => width - side - 8,
        };
        draw_lines(&mut self.overlay_rgba, width, text_width, &lines, 1);
    }
}

/// The overlay's lines on the run `t` trained beside the frames, standing at `s`.
fn training_lines(t: &Training, s: &LiveStatus, waiting: bool) -> Vec<String> {
    let budget = s.budget.unwrap_or(t.minutes() * 60.0);
    let mut lines = vec![format!(
        "training: step {}, {:.0} K samples/s, {:.0} of {:.0} s ({:.0} s left){}",
        s.step,
        s.samples_per_sec() / 1e3,
        s.seconds,
        budget,
        (budget - s.seconds).max(0.0),
        if s.paused { ", paused" } else { "" }
    )];
    let val = s.rows.iter().rev().find_map(|r| r.val);
    lines.push(match (s.train_loss.is_finite(), val) {
        (true, Some(v)) => format!("loss {:.4}, validation {v:.4} (grey, orange)", s.train_loss),
        (true, None) => format!("loss {:.4} (grey)", s.train_loss),
        _ => String::new(),
    });
    if waiting {
        lines.push(format!("loading the dataset for '{}' …", t.out().display()));
    }
    lines.retain(|l| !l.is_empty());
    lines
}

/// The run's training and validation losses against its seconds.
fn loss_curves(
    rows: &[nprt_net::training::loss_curves::LossRow],
) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let curve = |f: fn(&nprt_net::training::loss_curves::LossRow) -> Option<f64>| {
        rows.iter()
            .filter_map(|r| Some([r.seconds, f(r)?]))
            .collect()
    };
    (curve(|r| r.train), curve(|r| r.val))
}
