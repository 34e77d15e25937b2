//! The reference image that errors are measured against: a high-spp render with the most robust estimator we
//! have, or an EXR the user supplies. A rendered reference also keeps the variance of each pixel's mean,
//! `σ̂²/N`, so that its own noise can be reported (and subtracted, see [`super::ErrorMetrics`]).
//!
//! Rendered references are cached on disk under a key that hashes everything the image converges to (geometry,
//! materials, camera) and the reference's spp and seed, but not the estimator under study: every unbiased strategy
//! converges to the same image, so toggling strategies never invalidates the reference.

use crate::render::{Film, Footprint, Heuristic, MisSettings, RenderSettings, Strategy};
use crate::scene::{LightSelection, Scene};
use glam::Vec3;
use std::path::{Path, PathBuf};

/// The reference's own random streams: far from the small seeds users pick, so that the reference is independent
/// of the estimates it judges (the same seed would share camera jitter and, for the same strategy, every sample).
pub const REFERENCE_SEED: u64 = 0x05EE_D0F2_EFE2_E4CE;

/// The estimator behind rendered references: MIS of projected-solid-angle light sampling and Phong-BRDF sampling
/// with the power heuristic, triangles picked by power. It is robust on every bundled scene: light sampling
/// handles small and near lights, BRDF sampling glossy lobes (see the README's variance tables). The footprint
/// must be the estimates': a jittered reference converges to the box-filtered image, a centred one to the
/// value at each pixel's centre.
pub fn reference_settings(footprint: Footprint) -> RenderSettings {
    RenderSettings {
        footprint,
        strategy: Strategy::Mis,
        light_selection: LightSelection::Power,
        seed: REFERENCE_SEED,
        mis: MisSettings {
            techniques: [Strategy::ProjectedSolidAngle, Strategy::Brdf],
            heuristic: Heuristic::Power,
            samples: [1, 1],
        },
        ..Default::default()
    }
}

/// Where a reference came from.
#[derive(Clone, Debug, PartialEq)]
pub enum ReferenceOrigin {
    Rendered,
    Cache(PathBuf),
    File(PathBuf),
}

#[derive(Clone, Debug)]
pub struct Reference {
    pub width: u32,
    pub height: u32,
    /// Per-pixel radiance, row 0 at the top.
    pub mean: Vec<Vec3>,
    /// Per-pixel variance of the mean, `σ̂²/N`, when known (not for a plain EXR).
    pub var_of_mean: Option<Vec<Vec3>>,
    /// Samples per pixel (0 when unknown).
    pub spp: u32,
    /// Seconds it took to render (0 when loaded).
    pub seconds: f64,
    pub origin: ReferenceOrigin,
}

#[derive(Debug, thiserror::Error)]
pub enum ReferenceError {
    #[error("reference {}: {}", .0.display(), .1)]
    Read(PathBuf, String),
    #[error("reference {}: {}", .0.display(), .1)]
    Write(PathBuf, String),
    #[error("reference {}: {}×{} pixels, but the image is {}×{}", .path.display(), .found.0, .found.1, .expected.0, .expected.1)]
    Size { path: PathBuf, found: (u32, u32), expected: (u32, u32) },
}

impl Reference {
    /// A reference from an accumulated film.
    pub fn from_film(film: &Film, seconds: f64) -> Self {
        let spp = film.pixels.iter().map(|p| p.n).max().unwrap_or(0);
        Self {
            width: film.width,
            height: film.height,
            mean: film.means(),
            var_of_mean: Some(
                film.pixels
                    .iter()
                    .map(|p| if p.n < 2 { Vec3::ZERO } else { (p.variance() / p.n as f64).as_vec3() })
                    .collect(),
            ),
            spp,
            seconds,
            origin: ReferenceOrigin::Rendered,
        }
    }

    /// The reference's own noise: the mean over pixels and channels of `σ̂²/N`, in squared radiance. 0 when
    /// unknown.
    pub fn noise_mse(&self) -> f64 {
        super::error_over(&self.mean, self, None).reference_mse
    }

    /// The reference's own noise relative to its brightness: the mean of `(σ̂²/N) / (R² + ε)` (see relMSE in
    /// [`super::error_vs_reference`]). 0 when unknown.
    pub fn noise_rel_mse(&self) -> f64 {
        super::error_over(&self.mean, self, None).reference_rel_mse
    }

    /// Reads an EXR's first RGB(A) layer; a sibling `<stem>.var.exr`, if present, gives the variance of the mean.
    pub fn load_exr(path: &Path) -> Result<Self, ReferenceError> {
        let (width, height, mean) = read_rgb(path)?;
        let var_path = variance_path(path);
        let var_of_mean = match var_path.exists() {
            true => {
                let (w, h, var) = read_rgb(&var_path)?;
                if (w, h) != (width, height) {
                    return Err(ReferenceError::Size { path: var_path, found: (w, h), expected: (width, height) });
                }
                Some(var)
            }
            false => None,
        };
        Ok(Self { width, height, mean, var_of_mean, spp: 0, seconds: 0.0, origin: ReferenceOrigin::File(path.into()) })
    }

    /// Checks that the reference has the image's size.
    pub fn check_size(&self, width: u32, height: u32) -> Result<(), ReferenceError> {
        if (self.width, self.height) == (width, height) {
            return Ok(());
        }
        let path = match &self.origin {
            ReferenceOrigin::Cache(p) | ReferenceOrigin::File(p) => p.clone(),
            ReferenceOrigin::Rendered => PathBuf::from("(rendered)"),
        };
        Err(ReferenceError::Size { path, found: (self.width, self.height), expected: (width, height) })
    }

    /// Writes, when known, the variance of the mean to `<stem>.var.exr`, then the mean to `path`, each
    /// atomically: a mean on disk always has its variance beside it.
    pub fn save_exr(&self, path: &Path) -> Result<(), ReferenceError> {
        let write = |values: &[Vec3], to: &Path| {
            crate::render::write_image(&Film::from_means(self.width, self.height, values), to, 0.0)
                .map_err(|e| ReferenceError::Write(to.to_path_buf(), e.to_string()))
        };
        if let Some(var) = &self.var_of_mean {
            write(var, &variance_path(path))?;
        }
        write(&self.mean, path)
    }
}

/// `<stem>.var.exr` beside `path`.
pub fn variance_path(path: &Path) -> PathBuf {
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    path.with_file_name(format!("{stem}.var.exr"))
}

fn read_rgb(path: &Path) -> Result<(u32, u32, Vec<Vec3>), ReferenceError> {
    use exr::prelude::*;
    struct Pixels {
        width: usize,
        values: Vec<Vec3>,
    }
    let image = read_first_rgba_layer_from_file(
        path,
        |resolution, _| Pixels {
            width: resolution.width(),
            values: vec![Vec3::ZERO; resolution.width() * resolution.height()],
        },
        |pixels: &mut Pixels, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels.values[position.y() * pixels.width + position.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| ReferenceError::Read(path.to_path_buf(), e.to_string()))?;
    let size = image.layer_data.size;
    let values = image.layer_data.channel_data.pixels.values;
    if values.iter().any(|v| !v.is_finite()) {
        return Err(ReferenceError::Read(path.to_path_buf(), "non-finite pixel values".into()));
    }
    Ok((size.width() as u32, size.height() as u32, values))
}

/// The cache key of a rendered reference: FNV-1a over everything the image converges to (the footprint among
/// it), and the reference's spp. Names, file paths and the estimator under study are not part of it. The version
/// string changes when the renderer's images do (v2: error-bounded ray offsets).
pub fn reference_key(scene: &Scene, spp: u32, footprint: Footprint) -> u64 {
    let mut h = Fnv1a::new();
    h.bytes(b"illumlab-reference-v2");
    h.bytes(footprint.name().as_bytes());
    let s = reference_settings(footprint);
    h.u64(s.seed);
    h.u64(spp as u64);
    let c = &scene.camera;
    for v in [c.eye, c.target, c.up] {
        h.vec3(v);
    }
    h.f32(c.fov_y);
    h.u64(((c.width as u64) << 32) | c.height as u64);
    for t in &scene.triangles {
        t.v.iter().for_each(|v| h.vec3(*v));
        h.u64(t.material as u64);
    }
    for m in &scene.materials {
        h.vec3(m.kd);
        h.vec3(m.ks);
        h.f32(m.alpha);
        h.vec3(m.emission);
    }
    h.0
}

/// The cache file of a rendered reference in `folder`.
pub fn cache_path(folder: &Path, scene: &Scene, spp: u32, footprint: Footprint) -> PathBuf {
    let name: String =
        scene.name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect();
    let key = reference_key(scene, spp, footprint);
    folder.join(format!("{name}-{key:016x}-{spp}spp-{}.exr", footprint.name()))
}

/// The default cache folder: `references` in illumlab's cache folder (`$XDG_CACHE_HOME/illumlab`, else
/// `~/.cache/illumlab`).
pub fn default_cache_folder() -> Option<PathBuf> {
    crate::scene::user_cache_folder().map(|folder| folder.join("references"))
}

/// Loads a cached reference if one exists for this scene, spp and footprint.
pub fn load_cached(folder: &Path, scene: &Scene, spp: u32, footprint: Footprint) -> Option<Reference> {
    let path = cache_path(folder, scene, spp, footprint);
    let mut r = Reference::load_exr(&path).ok()?;
    r.check_size(scene.camera.width, scene.camera.height).ok()?;
    r.spp = spp;
    r.origin = ReferenceOrigin::Cache(path);
    Some(r)
}

/// Stores a rendered reference in the cache (creating the folder); returns the file written.
pub fn store_cached(
    folder: &Path,
    scene: &Scene,
    reference: &Reference,
    footprint: Footprint,
) -> Result<PathBuf, ReferenceError> {
    let path = cache_path(folder, scene, reference.spp, footprint);
    std::fs::create_dir_all(folder).map_err(|e| ReferenceError::Write(folder.to_path_buf(), e.to_string()))?;
    reference.save_exr(&path)?;
    Ok(path)
}

struct Fnv1a(u64);

impl Fnv1a {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn bytes(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ *b as u64).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    fn vec3(&mut self, v: Vec3) {
        [v.x, v.y, v.z].into_iter().for_each(|c| self.f32(c));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Renderer;
    use crate::scene::load_scene;

    const J: Footprint = Footprint::Jittered;

    fn small(name: &str) -> Scene {
        let mut scene = load_scene(name).expect("bundled");
        scene.camera.width = 8;
        scene.camera.height = 6;
        scene
    }

    #[test]
    fn key_follows_what_the_image_converges_to() {
        let scene = small("cornell-box");
        let k = reference_key(&scene, 64, J);
        assert_eq!(k, reference_key(&scene.clone(), 64, J));
        assert_ne!(k, reference_key(&scene, 128, J), "spp");
        let mut moved = scene.clone();
        moved.camera.eye.x += 1e-3;
        assert_ne!(k, reference_key(&moved, 64, J), "camera");
        let mut glossier = scene.clone();
        glossier.materials[0].alpha += 1.0;
        assert_ne!(k, reference_key(&glossier, 64, J), "material");
        let mut renamed = scene.clone();
        renamed.name = "other".into();
        assert_eq!(k, reference_key(&renamed, 64, J), "the name is not content");
        assert_ne!(k, reference_key(&scene, 64, Footprint::Centre), "footprint");
    }

    #[test]
    fn cache_round_trip_keeps_mean_and_variance() {
        let scene = small("cornell-box");
        let mut film = Film::new(8, 6);
        Renderer::new(std::sync::Arc::new(scene.clone()), reference_settings(J))
            .render_pass(&mut film, 0, 8, &|| false);
        let reference = Reference::from_film(&film, 0.5);
        assert_eq!(reference.spp, 8);
        assert!(reference.noise_mse() > 0.0 && reference.noise_rel_mse() > 0.0);
        let dir = tempfile::tempdir().expect("temp dir");
        assert!(load_cached(dir.path(), &scene, 8, J).is_none(), "nothing cached yet");
        let path = store_cached(dir.path(), &scene, &reference, J).expect("stored");
        assert!(variance_path(&path).exists());
        let back = load_cached(dir.path(), &scene, 8, J).expect("cached");
        assert_eq!(back.mean, reference.mean);
        assert_eq!(back.var_of_mean, reference.var_of_mean);
        assert_eq!(back.origin, ReferenceOrigin::Cache(path));
        let mut other = scene.clone();
        other.camera.fov_y += 1.0;
        assert!(load_cached(dir.path(), &other, 8, J).is_none(), "another camera misses");
    }

    #[test]
    fn bad_files_are_clear_errors() {
        let dir = tempfile::tempdir().expect("temp dir");
        let missing = dir.path().join("none.exr");
        let e = Reference::load_exr(&missing).expect_err("missing").to_string();
        assert!(e.contains("none.exr"), "{e}");
        let junk = dir.path().join("junk.exr");
        std::fs::write(&junk, b"not an exr").expect("write");
        let e = Reference::load_exr(&junk).expect_err("junk").to_string();
        assert!(e.contains("junk.exr"), "{e}");
        let r = Reference {
            width: 4,
            height: 4,
            mean: vec![Vec3::ONE; 16],
            var_of_mean: None,
            spp: 1,
            seconds: 0.0,
            origin: ReferenceOrigin::File(junk),
        };
        let e = r.check_size(8, 6).expect_err("size").to_string();
        assert!(e.contains("4×4") && e.contains("8×6"), "{e}");
    }
}
