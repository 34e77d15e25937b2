//! The scene file (TOML):
//!
//! ```toml
//! [camera]
//! eye = [0.0, 1.0, 3.9]
//! target = [0.0, 1.0, 0.0]
//! up = [0.0, 1.0, 0.0]
//! fov_y = 39.3          # vertical field of view, degrees
//! width = 256
//! height = 256
//!
//! [[mesh]]
//! obj = "cornell-box.obj"   # relative to the scene file
//! [mesh.materials.TallBlock] # optional overrides of the MTL, by material name
//! ks = [0.6, 0.6, 0.6]
//! alpha = 200.0
//! ```

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    pub camera: CameraSpec,
    #[serde(default)]
    pub mesh: Vec<MeshSpec>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    // f64: a scene kilometres from the origin is rebased before it is rounded to f32.
    pub eye: [f64; 3],
    pub target: [f64; 3],
    pub up: [f32; 3],
    pub fov_y: f32,
    pub width: u32,
    pub height: u32,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    pub obj: String,
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialOverride>,
}

/// Replaces the MTL's values for one material; absent fields keep the MTL's.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverride {
    pub kd: Option<[f32; 3]>,
    pub ks: Option<[f32; 3]>,
    pub alpha: Option<f32>,
    pub ke: Option<[f32; 3]>,
}

impl SceneFile {
    /// Parses the TOML text; the error is one line with the line number.
    pub fn parse(text: &str) -> Result<Self, String> {
        toml::from_str(text).map_err(|e| {
            let line = e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1);
            let message = e.message().trim().replace('\n', " ");
            match line {
                Some(l) => format!("line {l}: {message}"),
                None => message,
            }
        })
    }
}
