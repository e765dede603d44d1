//! nprt-py: nprt from Python, the compiled part (`nprt._nprt`) of the `nprt` package in
//! `python/`. It owns the conversions between nprt's types and Python's (numpy arrays in and
//! out, exceptions carrying the CLI's messages, keyword arguments whose defaults are the
//! libraries' option types' own) and nothing else: every stage's work is its library's, called
//! as the command line calls it, with the GIL released while it runs.

mod argument;
mod arrays;
mod bake;
mod choice;
mod dataset;
mod error;
mod evaluate;
mod export;
mod generate;
mod image;
mod interruptible;
mod model;
mod model_info;
mod paper;
mod render;
mod scene;
mod train;

use pyo3::prelude::*;

/// Runs nprt's command line on `argv` (the program's name first), as the `nprt` binary does;
/// returns its exit status. The package's `nprt` command and `python -m nprt` call it.
#[pyfunction]
fn cli(py: Python<'_>, argv: Vec<std::ffi::OsString>) -> i32 {
    py.detach(|| nprt::main_with(argv))
}

#[pymodule]
fn _nprt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<scene::Scene>()?;
    m.add_class::<scene::EnvMap>()?;
    m.add_class::<dataset::Dataset>()?;
    m.add_class::<dataset::DatasetViews>()?;
    m.add_class::<model::Model>()?;
    m.add_function(wrap_pyfunction!(scene::load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene::open_envmap, m)?)?;
    m.add_function(wrap_pyfunction!(scene::reference, m)?)?;
    m.add_function(wrap_pyfunction!(scene::look_at, m)?)?;
    m.add_function(wrap_pyfunction!(generate::generate, m)?)?;
    m.add_function(wrap_pyfunction!(train::train, m)?)?;
    m.add_function(wrap_pyfunction!(train::train_deep_shading, m)?)?;
    m.add_function(wrap_pyfunction!(export::export, m)?)?;
    m.add_function(wrap_pyfunction!(model_info::model_info, m)?)?;
    m.add_function(wrap_pyfunction!(paper::paper, m)?)?;
    m.add_function(wrap_pyfunction!(bake::bake, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(image::write_image, m)?)?;
    m.add_function(wrap_pyfunction!(image::read_image, m)?)?;
    m.add_function(wrap_pyfunction!(cli, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The designs `train` and `model_info` take, as the command line's `--arch` lists them.
    m.add(
        "DESIGNS",
        nprt_net::Design::ALL.map(nprt_net::Design::name).to_vec(),
    )?;
    Ok(())
}
