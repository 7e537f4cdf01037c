//! # streaks-python
//!
//! The native module `streaks._streaks` of the Python package `streaks` (built by maturin from
//! `python/pyproject.toml`): stereo researchers load a scene, render a pair in-process and get
//! numpy arrays with the same values the `streaks stereo` command writes, and read the
//! project's files (PFM, PNG, EXR) with the project's readers.
//!
//! Everything here is a thin binding over the library crates: scenes are loaded with the
//! renderer's untrusted-scene checks ([`streaks_render::scene::Scene::load_with`]), views are
//! framed with [`streaks_render::view::frame_view`], pairs are rendered with
//! [`streaks_stereo::render::render_pair`] and saved with
//! [`streaks_dataset::write::write_pair`]. Every error becomes the Python exception
//! `streaks.StreaksError` (a `ValueError`) whose message is the whole chain of causes,
//! naming the file and the reason; no panic crosses into Python (PyO3 turns one into a
//! `PanicException`, which the library crates never raise on bad input).
//!
//! The module is tested from pytest (`python/tests`): an extension module cannot link a Rust
//! test binary against libpython.

#![deny(missing_docs)]

use pyo3::create_exception;
use pyo3::prelude::*;

mod arrays;
mod dataset;
mod io;
mod options;
mod pair;
mod scene;
mod stereo;

create_exception!(
    streaks,
    StreaksError,
    pyo3::exceptions::PyValueError,
    "An error of the streaks library: a scene, image or option it cannot use. The message \
     names the file (where there is one) and the reason."
);

/// The exception of an error and its causes, joined by `": "` as the command prints them.
pub(crate) fn error(e: &(dyn std::error::Error + 'static)) -> PyErr {
    StreaksError::new_err(chain(e))
}

/// An error and its causes as one message, joined by `": "`.
pub(crate) fn chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut message = e.to_string();
    let mut source = e.source();
    while let Some(cause) = source {
        let text = cause.to_string();
        if !message.contains(&text) {
            message.push_str(": ");
            message.push_str(&text);
        }
        source = cause.source();
    }
    message
}

/// The native module: the classes `Scene`, `Pair` and `Dataset`, the exception `StreaksError`,
/// the readers `read_pfm`, `read_png` and `read_exr`, and the benchmark's `disparity` methods
/// and `score`.
#[pymodule]
fn _streaks(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("StreaksError", m.py().get_type::<StreaksError>())?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<pair::Pair>()?;
    m.add_class::<dataset::Dataset>()?;
    m.add_function(wrap_pyfunction!(io::read_pfm, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_png, m)?)?;
    m.add_function(wrap_pyfunction!(io::read_exr, m)?)?;
    m.add_function(wrap_pyfunction!(stereo::disparity, m)?)?;
    m.add_function(wrap_pyfunction!(stereo::score, m)?)?;
    m.add(
        "DEFAULT_BASELINE",
        streaks_stereo::rig::Rig::DEFAULT_BASELINE,
    )?;
    Ok(())
}
