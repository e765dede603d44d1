//! Speed measurements of the networks: training samples/s and inference per frame, and the
//! PyTorch peer the training rate is compared with.

pub mod pytorch_peer;
pub mod throughput;
