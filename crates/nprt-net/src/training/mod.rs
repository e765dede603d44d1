//! Training: the training set in memory, batches, the learning-rate schedule, the one training
//! loop with checkpoints and exact resume, each engine's steps as the loop takes them, the
//! Neural PRT objective run through it, validation, calibration and loss curves, the
//! recommended recipe (a design with every choice of its training and run time), the radiance
//! cache's online training, and a long run's visits landed into its folder.

pub mod batch;
pub mod cache_trainer;
pub mod calibration;
pub mod checkpoint;
pub mod epoch_plan;
pub mod host_steps;
#[cfg(feature = "gpu")]
pub mod kernel_steps;
pub mod loss_curves;
pub mod lr_schedule;
pub mod minutes;
pub mod nprt_objective;
pub mod recipe;
pub mod run_length;
pub mod schedule;
pub mod snapshot;
pub mod train_options;
pub mod training_loop;
pub mod training_set;
pub mod validation;
pub mod visits;
