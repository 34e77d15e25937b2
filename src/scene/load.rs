//! Loading: scene file (TOML) → OBJ meshes (`obj`, on all cores) and their MTL materials (tobj) → [`Scene`].
//! Files are read through a [`Source`]: the file system, or the scenes compiled into the binary.

use super::bundled::{self, BundledScene};
use super::file::{MaterialOverride, MeshSpec, SceneFile};
use super::material::validate;
use super::mtl::clean_mtl;
use super::obj::read_obj;
use super::{Camera, Material, Scene, SceneError};
use glam::{DVec3, Vec3};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Where a scene's files come from.
enum Source {
    Dir(PathBuf),
    Bundled(&'static BundledScene),
    /// Files held in memory, by name (the fuzzer's input).
    Memory(Vec<(PathBuf, String)>),
}

impl Source {
    fn read(&self, rel: &Path) -> Result<String, SceneError> {
        match self {
            Source::Dir(dir) => {
                let path = dir.join(rel);
                std::fs::read_to_string(&path).map_err(|cause| SceneError::Io { path, cause })
            }
            Source::Bundled(scene) => scene.file(rel).map(str::to_owned).ok_or_else(|| SceneError::Io {
                path: rel.to_path_buf(),
                cause: std::io::Error::new(std::io::ErrorKind::NotFound, "not in the bundled scene"),
            }),
            Source::Memory(files) => {
                let rel = rel.strip_prefix(".").unwrap_or(rel);
                files.iter().find(|(name, _)| name == rel).map(|(_, text)| text.clone()).ok_or_else(|| SceneError::Io {
                    path: rel.to_path_buf(),
                    cause: std::io::Error::new(std::io::ErrorKind::NotFound, "not among the files given"),
                })
            }
        }
    }
}

/// Loads `name_or_path`: a scene file (`.toml`), a bare `.obj` (framed by an automatic camera), or the name of a
/// bundled scene.
pub fn load_scene(name_or_path: &str) -> Result<Scene, SceneError> {
    let path = Path::new(name_or_path);
    if path.is_file() {
        return load_scene_file(path);
    }
    if let Some(scene) = bundled::find(name_or_path) {
        let toml_name = format!("{}.toml", scene.name);
        return load_from(&Source::Bundled(scene), Path::new(&toml_name), scene.name);
    }
    if path.extension().is_some() || name_or_path.contains(std::path::MAIN_SEPARATOR) {
        return Err(SceneError::Io {
            path: path.to_path_buf(),
            cause: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
        });
    }
    Err(SceneError::UnknownScene { name: name_or_path.to_string(), known: bundled::names().join(", ") })
}

/// Loads a scene from three texts that stand for `scene.toml`, `scene.obj` and `scene.mtl`, given one after
/// the other, separated by NUL bytes (as the loader's fuzz target and its corpus replay feed it). Never panics:
/// any input is a scene or an error.
pub fn load_scene_from_bytes(data: &[u8]) -> Result<Scene, SceneError> {
    let mut parts = data.splitn(3, |&b| b == 0).map(|p| String::from_utf8_lossy(p).into_owned());
    let (toml, obj, mtl) =
        (parts.next().unwrap_or_default(), parts.next().unwrap_or_default(), parts.next().unwrap_or_default());
    let files = vec![("scene.toml".into(), toml), ("scene.obj".into(), obj), ("scene.mtl".into(), mtl)];
    load_from(&Source::Memory(files), Path::new("scene.toml"), "fuzz")
}

/// Loads a scene file from disk (`.toml`, or `.obj` with an automatic camera).
pub fn load_scene_file(path: &Path) -> Result<Scene, SceneError> {
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let file_name = PathBuf::from(path.file_name().unwrap_or_default());
    let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string();
    let source = Source::Dir(dir);
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
        let spec = MeshSpec { obj: file_name.to_string_lossy().into_owned(), materials: BTreeMap::new() };
        let mut meshes = Meshes::default();
        meshes.load(&source, &spec, path)?;
        let camera = auto_camera(meshes.bounds());
        return meshes.into_scene(name, camera, path);
    }
    load_from(&source, &file_name, &name)
}

fn load_from(source: &Source, toml_path: &Path, name: &str) -> Result<Scene, SceneError> {
    let text = source.read(toml_path)?;
    let file =
        SceneFile::parse(&text).map_err(|message| SceneError::Toml { path: toml_path.to_path_buf(), message })?;
    let c = &file.camera;
    let camera = WorldCamera {
        eye: c.eye.into(),
        target: c.target.into(),
        up: c.up.into(),
        fov_y: c.fov_y,
        width: c.width,
        height: c.height,
    };
    camera
        .local(camera.target)
        .validate()
        .map_err(|e| SceneError::Toml { path: toml_path.to_path_buf(), message: e.to_string() })?;
    let mut meshes = Meshes::default();
    for spec in &file.mesh {
        meshes.load(source, spec, toml_path)?;
    }
    meshes.into_scene(name.to_string(), camera, toml_path)
}

/// A camera in the coordinates of the scene's files (f64, as they may be far from the origin).
struct WorldCamera {
    eye: DVec3,
    target: DVec3,
    up: Vec3,
    fov_y: f32,
    width: u32,
    height: u32,
}

impl WorldCamera {
    /// The camera relative to `origin`, in f32.
    fn local(&self, origin: DVec3) -> Camera {
        Camera {
            eye: (self.eye - origin).as_vec3(),
            target: (self.target - origin).as_vec3(),
            up: self.up,
            fov_y: self.fov_y,
            width: self.width,
            height: self.height,
        }
    }
}

/// Triangles and materials gathered from the meshes of one scene.
#[derive(Default)]
struct Meshes {
    /// The vertices of all meshes in the files' coordinates, f64: rebased and rounded to f32 once every mesh is
    /// in. They include those no triangle uses, which neither bound the scene nor need be finite.
    vertices: Vec<DVec3>,
    /// Per triangle, its vertices' indices in `vertices`.
    triangles: Vec<[u32; 3]>,
    material_ids: Vec<u32>,
    materials: Vec<Material>,
    names: Vec<String>,
    default_material: Option<u32>,
    /// What was loaded differently from what the files say (ignored statements, missing files), one line each.
    warnings: Vec<String>,
}

impl Meshes {
    /// `scene_file` is named in errors about the overrides it wrote.
    fn load(&mut self, source: &Source, spec: &MeshSpec, scene_file: &Path) -> Result<(), SceneError> {
        let obj_path = PathBuf::from(&spec.obj);
        let obj_dir = obj_path.parent().map(Path::to_path_buf).unwrap_or_default();
        let text = source.read(&obj_path)?;
        let mut mtl_paths: Vec<PathBuf> = Vec::new();
        let geometry = read_obj(&text, &obj_path, |mtl| {
            let mtl_path = obj_dir.join(mtl);
            let text = match source.read(&mtl_path) {
                Ok(text) => text,
                Err(SceneError::Io { path, cause }) if cause.kind() == std::io::ErrorKind::NotFound => {
                    self.warnings.push(format!(
                        "{}: no such MTL file ({}): its materials are replaced by the default grey (k_d = 0.5)",
                        obj_path.display(),
                        path.display()
                    ));
                    String::new()
                }
                Err(e) => return Err(e),
            };
            let clean = clean_mtl(&text).map_err(|message| SceneError::Mtl { path: mtl_path.clone(), message })?;
            if !clean.ignored.is_empty() {
                self.warnings.push(format!(
                    "{}: ignored (the Phong model has no use for them): {}",
                    mtl_path.display(),
                    clean.ignored.join(", ")
                ));
            }
            let (materials, _) = tobj::load_mtl_buf(&mut clean.text.as_bytes())
                .map_err(|e| SceneError::Mtl { path: mtl_path.clone(), message: e.to_string() })?;
            mtl_paths.push(mtl_path);
            Ok(materials)
        })?;
        drop(text);
        let materials = &geometry.materials;
        let mtl_path = mtl_paths.pop().unwrap_or_else(|| obj_path.clone());
        if !geometry.unknown_materials.is_empty() {
            self.warnings.push(format!(
                "{}: usemtl of material(s) no MTL defines ({}): those faces get the default grey (k_d = 0.5)",
                obj_path.display(),
                geometry.unknown_materials.join(", ")
            ));
        }

        for name in spec.materials.keys() {
            if !materials.iter().any(|m| &m.name == name) {
                let known: Vec<&str> = materials.iter().map(|m| m.name.as_str()).collect();
                return Err(SceneError::Mesh {
                    path: obj_path,
                    message: format!(
                        "override for material '{name}', which its MTL does not define (it has: {})",
                        known.join(", ")
                    ),
                });
            }
        }
        let base = self.materials.len() as u32;
        for m in materials {
            // Bad values are reported against the file that wrote them: the MTL, or the scene file's override.
            let blame =
                |path: &Path, e: SceneError| SceneError::Mesh { path: path.to_path_buf(), message: e.to_string() };
            validate(&from_mtl(m, None), &m.name).map_err(|e| blame(&mtl_path, e))?;
            let material = from_mtl(m, spec.materials.get(&m.name));
            validate(&material, &m.name).map_err(|e| blame(scene_file, e))?;
            self.materials.push(material);
            self.names.push(m.name.clone());
        }

        // Only the vertices some triangle uses need be finite.
        let positions = &geometry.positions;
        let not_finite = geometry.triangles.par_iter().enumerate().find_map_first(|(t, corners)| {
            corners.iter().find(|&&i| !positions[i as usize].is_finite()).map(|&i| (t, i))
        });
        if let Some((t, i)) = not_finite {
            let run = geometry.runs.iter().rev().find(|r| r.first <= t).expect("the first run starts at 0");
            return Err(SceneError::Mesh {
                path: obj_path,
                message: format!("vertex {} of object '{}' is not finite (NaN or infinity)", i + 1, run.object),
            });
        }
        if self.vertices.len() + positions.len() > u32::MAX as usize {
            return Err(SceneError::Mesh { path: obj_path, message: "more than 2³² vertices in the scene".into() });
        }
        let first = self.vertices.len() as u32;
        self.vertices.extend_from_slice(positions);
        self.triangles.extend(geometry.triangles.iter().map(|t| t.map(|i| first + i)));
        for (r, run) in geometry.runs.iter().enumerate() {
            let end = geometry.runs.get(r + 1).map_or(geometry.triangles.len(), |next| next.first);
            if end == run.first {
                continue;
            }
            let material = match run.material {
                Some(id) => base + id as u32,
                None => self.default_material(),
            };
            let count = self.material_ids.len() + end - run.first;
            self.material_ids.resize(count, material);
        }
        Ok(())
    }

    fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.materials.push(Material::default());
            self.names.push("(no material)".into());
            self.materials.len() as u32 - 1
        })
    }

    /// The bounding box of the vertices the triangles use (infinite and inverted when there is none).
    fn bounds(&self) -> (DVec3, DVec3) {
        let empty = || (DVec3::INFINITY, DVec3::NEG_INFINITY);
        self.triangles
            .par_iter()
            .fold(empty, |(lo, hi), t| {
                t.iter().fold((lo, hi), |(lo, hi), &i| {
                    (lo.min(self.vertices[i as usize]), hi.max(self.vertices[i as usize]))
                })
            })
            .reduce(empty, |(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
    }

    /// Rebases a scene far from the origin (by more than 16 times its size) to its bounds' centre, in f64, then
    /// rounds to f32: it then renders as it would at the origin (f32 positions 10⁵ m out are 8 mm apart).
    fn into_scene(self, name: String, camera: WorldCamera, path: &Path) -> Result<Scene, SceneError> {
        let (lo, hi) = self.bounds();
        let (centre, radius) = (0.5 * (lo + hi), 0.5 * (hi - lo).length());
        let origin = if centre.is_finite() && centre.length() > 16.0 * radius.max(1e-3) { centre } else { DVec3::ZERO };
        let vertex = |i: u32| (self.vertices[i as usize] - origin).as_vec3();
        let positions: Vec<[Vec3; 3]> = self.triangles.par_iter().map(|t| t.map(vertex)).collect();
        // Only the triangles' f32 positions are needed while the tree is built.
        drop((self.vertices, self.triangles));
        let mut scene =
            Scene::new(name, camera.local(origin), &positions, &self.material_ids, self.materials, self.names)
                .map_err(|e| match e {
                    SceneError::Invalid(message) => SceneError::Mesh { path: path.to_path_buf(), message },
                    other => other,
                })?;
        scene.warnings.splice(0..0, self.warnings);
        scene.origin = origin;
        Ok(scene)
    }
}

/// MTL → Phong: Kd → k_d, Ks → k_s, Ns → α, Ke → L_e; missing values are 0 (α: 1). Then the overrides.
fn from_mtl(m: &tobj::Material, o: Option<&MaterialOverride>) -> Material {
    let o = o.cloned().unwrap_or_default();
    let f32s = |c: [f64; 3]| c.map(|x| x as f32);
    let v = |x: Option<[f32; 3]>| x.map(Vec3::from).unwrap_or(Vec3::ZERO);
    Material {
        kd: v(o.kd.or(m.diffuse.map(f32s))),
        ks: v(o.ks.or(m.specular.map(f32s))),
        alpha: o.alpha.or(m.shininess.map(|a| a as f32)).unwrap_or(1.0),
        emission: v(o.ke.or(m.emissive.map(f32s))),
    }
}

/// A camera for a bare OBJ: looks at the bounding box's centre along −z from far enough to see all of it.
fn auto_camera((lo, hi): (DVec3, DVec3)) -> WorldCamera {
    let (centre, radius) = if lo.is_finite() && hi.is_finite() {
        (0.5 * (lo + hi), (0.5 * (hi - lo).length()).max(1e-3))
    } else {
        (DVec3::ZERO, 1.0)
    };
    let fov_y = 40.0f32;
    let distance = radius / (0.5 * fov_y as f64).to_radians().sin();
    WorldCamera {
        eye: centre + DVec3::new(0.0, 0.0, distance),
        target: centre,
        up: Vec3::Y,
        fov_y,
        width: 512,
        height: 512,
    }
}
