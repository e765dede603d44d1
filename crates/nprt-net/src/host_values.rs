//! A burn tensor's values read back as f32 on the host, for the engines and reports that work
//! on plain slices.

/// A tensor's values as f32 on the host.
pub fn host_values(data: burn::tensor::TensorData) -> Vec<f32> {
    data.convert::<f32>()
        .try_into_vec::<f32>()
        .expect("converted to f32")
}
