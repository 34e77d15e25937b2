//! What can go wrong when loading a scene. Every message is one line and names the file or value at fault.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    // Not a `source` field: the message already says it, and callers print the whole chain.
    #[error("cannot read {}: {cause}", path.display())]
    Io { path: PathBuf, cause: std::io::Error },
    #[error("{}: {message}", path.display())]
    Toml { path: PathBuf, message: String },
    #[error("{}: {message}", path.display())]
    Obj { path: PathBuf, message: String },
    #[error("{}: {message}", path.display())]
    Mtl { path: PathBuf, message: String },
    #[error("{}: {message}", path.display())]
    Mesh { path: PathBuf, message: String },
    #[error("camera: {0}")]
    Camera(String),
    #[error("non-finite {0} (NaN or infinity)")]
    NonFinite(String),
    #[error("{0}")]
    Invalid(String),
    #[error("unknown scene '{name}': no such file, and not a bundled scene ({known})")]
    UnknownScene { name: String, known: String },
}
