//! Nothing: the crate exists for its benchmark (benches/bvh.rs).
