//! Any bytes given as a model folder (model.json and weights.safetensors) must be refused or
//! load: never a panic or an abort on a huge allocation (the loader refuses sizes no network
//! has and weights holding NaN or infinity). Input: a little-endian u32 length, that many bytes of model.json,
//! then the bytes of weights.safetensors.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nprt_net::model::folder::{CONFIG_FILE, WEIGHTS_FILE};

fuzz_target!(|data: &[u8]| {
    let Some((len, rest)) = data.split_first_chunk::<4>() else {
        return;
    };
    let len = (u32::from_le_bytes(*len) as usize).min(rest.len());
    let (json, weights) = rest.split_at(len);
    let dir = std::env::temp_dir().join(format!("nprt-fuzz-model-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(CONFIG_FILE), json).unwrap();
    std::fs::write(dir.join(WEIGHTS_FILE), weights).unwrap();
    if let Ok((file, _)) = nprt_net::load_model(&dir) {
        assert!(file.config.encoder_width <= nprt_net::network::encoder::MAX_INPUT_WIDTH);
    }
});
