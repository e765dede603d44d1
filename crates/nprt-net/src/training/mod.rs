//! Training: the training set in memory, batches, the learning-rate schedule, the one training
//! loop with checkpoints and exact resume, each engine's steps as the loop takes them, the
//! Neural PRT objective run through it, validation, calibration and loss curves, the
//! recommended recipe (a design with every choice of its training and run time), the radiance
//! cache's online training, and a long run's visits landed into its folder.

pub mod batch;
pub mod cache_trainer;
pub mod calibration;
pub mod checkpoint;
mod divergence;
pub mod epoch_plan;
pub mod host_steps;
#[cfg(feature = "gpu")]
pub mod kernel_steps;
pub mod live;
pub mod loss_curves;
pub mod lr_schedule;
pub mod minutes;
pub mod nprt_objective;
mod objective;
pub mod recipe;
mod run;
pub mod run_length;
mod run_live;
pub mod schedule;
pub mod snapshot;
mod time_split;
pub mod train_options;
pub mod training_loop;
pub mod training_set;
pub mod validation;
pub mod visits;
