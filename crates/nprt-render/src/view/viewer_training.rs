//! The viewer's side of a run trained beside its frames: the run's newest model taken into
//! the frame, what the run did said, the dataset's maps as the lightings, and the run saved
//! when the window closes.

use anyhow::Result;
use nprt_scene::EnvMap;

use super::live_training::Training;
use super::viewer_state::Viewer;
use crate::relight::{FrameCache, Relighter};

/// The share of the wall time the window's own work (a frame with newer weights, a reference
/// pass) may take while the run trains; the rest is the run's. Measured in docs/model.md
/// (training in the viewer).
const WINDOW_SHARE: f64 = 0.2;

impl Viewer<'_> {
    /// Whether the window's work waits, so that the run keeps most of the machine: while the
    /// run trains, each piece of work is followed by four times as long without (input is
    /// served at once; a paused or ended run leaves the machine to the window).
    pub(super) fn pacing(&self) -> bool {
        let running = self.training.is_some() && self.said.paused_at.is_none() && !self.said.ended;
        let rest = |secs: f64| secs * (1.0 / WINDOW_SHARE - 1.0);
        running
            && !self.models.is_empty()
            && (self.worked).is_some_and(|(end, secs)| end.elapsed().as_secs_f64() < rest(secs))
    }

    /// Takes the run's newest model, if one came.
    pub(super) fn take_newest_model(&mut self) -> Result<()> {
        let Some(t) = &mut self.training else {
            return Ok(());
        };
        if let Some((file, net)) = t.newest_model() {
            match self.models.first_mut() {
                Some(m) => m.set_weights(file, net)?,
                None => {
                    let mut m = Relighter::new(file, net, self.opts.engine)?;
                    m.set_precision(self.opts.precision)?;
                    self.models.push(m);
                }
            }
            self.cache = FrameCache::default();
            self.stale = true;
        }
        Ok(())
    }

    /// Says what the run did since the last frame: paused, resumed, saved, ended.
    pub(super) fn say_training(&mut self) {
        let Some(t) = &mut self.training else {
            return;
        };
        let status = t.status();
        let said = &mut self.said;
        if status.paused != said.paused_at.is_some() {
            // A run resumes from the step it was paused at; the status, polled once a frame,
            // may already count a step taken since.
            let (what, step) = match said.paused_at.take() {
                Some(at) => ("resumed", at),
                None => {
                    said.paused_at = Some(status.step);
                    ("paused", status.step)
                }
            };
            self.message = format!("training {what} at step {step}");
            println!("nprt view: {}", self.message);
        }
        if status.saved_at != said.saved_at {
            said.saved_at = status.saved_at;
            let step = status.saved_at.unwrap_or(0);
            self.message = format!("saved '{}' at step {step}", t.out().display());
            println!("nprt view: {}", self.message);
        }
        if let (false, Some(outcome)) = (said.ended, t.outcome()) {
            said.ended = true;
            self.message = match outcome {
                Ok(s) => format!(
                    "training ended at step {} (X: {} minutes more)",
                    s.steps, self.opts.extend_minutes
                ),
                Err(e) => format!("training failed: {e}"),
            };
            println!("nprt view: {}", self.message);
        }
    }
}

/// Stops the viewer's run, saved, and says where it stands.
pub(super) fn finish_training(t: Training) -> Result<()> {
    let out = t.out().display().to_string();
    let minutes = t.minutes();
    if let Some(s) = t.finish()? {
        println!(
            "nprt view: trained {} steps, {:.2} M samples in {:.1} s ({:.0} K samples/s); \
             model in '{out}' (`nprt train --minutes {minutes}` with the same flags, or `nprt \
             view --train` again, continues it)",
            s.steps,
            s.samples as f64 / 1e6,
            s.seconds,
            s.samples as f64 / s.seconds.max(1e-9) / 1e3,
        );
    }
    Ok(())
}

/// Pulls the dataset's maps out as the viewer's lightings: the held-out ones first.
pub(super) fn dataset_maps(
    manifest: &nprt_data::dataset::Manifest,
) -> Result<Vec<(String, EnvMap)>> {
    let s = &manifest.settings;
    let held_out = s.test_maps.iter().map(|&m| (m, "held out"));
    let trained = s.train_maps.iter().map(|&m| (m, "trained on"));
    (held_out.chain(trained))
        .map(|(m, what)| {
            let map = nprt_net::training::training_set::open_recorded_map(manifest, m)?;
            Ok((format!("{} ({what})", s.envmaps[m].spec), map))
        })
        .collect()
}
