//! A step is a function that sets a [`Session`]: [`Step::apply`]. [`Step::from_session`] is its inverse (the
//! viewer's "save this view as a step"). Also the step's sub-tables: camera, materials and MIS.

use super::file::{heuristic, number, strategy, string, triple, whole};
use super::{Caption, Step, vec3};
use crate::render::{MisSettings, RenderSettings, Strategy};
use crate::scene::{Camera, load_scene};
use crate::session::Session;
use toml::{Table, Value};

/// A camera in a tour file; a missing field keeps the current camera's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraStep {
    pub eye: Option<[f32; 3]>,
    pub target: Option<[f32; 3]>,
    pub up: Option<[f32; 3]>,
    /// Vertical field of view, degrees.
    pub fov_y: Option<f32>,
}

impl CameraStep {
    pub(super) fn parse(v: &Value) -> Result<Self, String> {
        let t = table(v, "{ eye = [x, y, z], target = [x, y, z], up = [x, y, z], fov_y = degrees }")?;
        let mut c = CameraStep::default();
        for (k, v) in t {
            let at = |p: String| format!("`{k}`: {p}");
            match k.as_str() {
                "eye" => c.eye = Some(triple(v, -1e7, 1e7).map_err(at)?),
                "target" => c.target = Some(triple(v, -1e7, 1e7).map_err(at)?),
                "up" => c.up = Some(triple(v, -1e7, 1e7).map_err(at)?),
                "fov_y" => c.fov_y = Some(number(v, 1e-3, 179.999).map_err(at)? as f32),
                _ => return Err(format!("unknown camera field `{k}` (eye, target, up, fov_y)")),
            }
        }
        Ok(c)
    }

    pub(super) fn to_toml(self) -> Value {
        let mut t = Table::new();
        let arr = |a: [f32; 3]| Value::Array(a.iter().map(|x| Value::Float(*x as f64)).collect());
        for (k, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if let Some(v) = v {
                t.insert(k.into(), arr(v));
            }
        }
        if let Some(f) = self.fov_y {
            t.insert("fov_y".into(), Value::Float(f as f64));
        }
        Value::Table(t)
    }

    fn on(&self, c: Camera) -> Camera {
        Camera {
            eye: self.eye.map_or(c.eye, vec3),
            target: self.target.map_or(c.target, vec3),
            up: self.up.map_or(c.up, vec3),
            fov_y: self.fov_y.unwrap_or(c.fov_y),
            ..c
        }
    }
}

/// A material of the scene changed by name; a missing field keeps the current value.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialStep {
    pub name: String,
    pub kd: Option<[f32; 3]>,
    pub ks: Option<[f32; 3]>,
    /// Phong exponent α.
    pub alpha: Option<f32>,
}

impl MaterialStep {
    pub(super) fn parse(v: &Value) -> Result<Self, String> {
        let t = table(v, "{ name = \"…\", kd = [r, g, b], ks = [r, g, b], alpha = α }")?;
        let mut m = MaterialStep::default();
        for (k, v) in t {
            let at = |p: String| format!("material `{k}`: {p}");
            match k.as_str() {
                "name" => m.name = string(v).map_err(at)?,
                "kd" => m.kd = Some(triple(v, 0.0, 1.0).map_err(at)?),
                "ks" => m.ks = Some(triple(v, 0.0, 1.0).map_err(at)?),
                "alpha" => m.alpha = Some(number(v, 0.0, 1e6).map_err(at)? as f32),
                _ => return Err(format!("unknown material field `{k}` (name, kd, ks, alpha)")),
            }
        }
        if m.name.is_empty() {
            return Err("a material needs the `name` of one of the scene's materials".into());
        }
        Ok(m)
    }

    pub(super) fn to_toml(&self) -> Value {
        let mut t = Table::new();
        let arr = |a: [f32; 3]| Value::Array(a.iter().map(|x| Value::Float(*x as f64)).collect());
        t.insert("name".into(), Value::String(self.name.clone()));
        for (k, v) in [("kd", self.kd), ("ks", self.ks)] {
            if let Some(v) = v {
                t.insert(k.into(), arr(v));
            }
        }
        if let Some(a) = self.alpha {
            t.insert("alpha".into(), Value::Float(a as f64));
        }
        Value::Table(t)
    }
}

/// MIS's settings in a tour file; a missing field keeps the current value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MisStep {
    pub techniques: Option<[Strategy; 2]>,
    pub heuristic: Option<crate::render::Heuristic>,
    /// Directions per pixel sample from each technique.
    pub samples: Option<[u32; 2]>,
}

impl MisStep {
    pub(super) fn parse(v: &Value) -> Result<Self, String> {
        let t = table(v, "{ techniques = [\"emitter\", \"brdf\"], heuristic = \"power\", samples = [1, 1] }")?;
        let mut m = MisStep::default();
        for (k, v) in t {
            let at = |p: String| format!("mis `{k}`: {p}");
            match (k.as_str(), v) {
                ("techniques", Value::Array(a)) if a.len() == 2 => {
                    let [t0, t1] = [strategy(&a[0]).map_err(at)?, strategy(&a[1]).map_err(at)?];
                    if t0 == Strategy::Mis || t1 == Strategy::Mis {
                        return Err(at("MIS cannot be its own technique".into()));
                    }
                    m.techniques = Some([t0, t1]);
                }
                ("samples", Value::Array(a)) if a.len() == 2 => {
                    let [n0, n1] = [whole(&a[0], 0, 1024).map_err(at)?, whole(&a[1], 0, 1024).map_err(at)?];
                    if n0 + n1 == 0 {
                        return Err(at("not both 0".into()));
                    }
                    m.samples = Some([n0 as u32, n1 as u32]);
                }
                ("heuristic", v) => m.heuristic = Some(heuristic(v).map_err(at)?),
                ("techniques" | "samples", _) => return Err(at("expected a list of two".into())),
                _ => return Err(format!("unknown mis field `{k}` (techniques, heuristic, samples)")),
            }
        }
        Ok(m)
    }

    pub(super) fn to_toml(self) -> Value {
        let mut t = Table::new();
        if let Some(ts) = self.techniques {
            t.insert("techniques".into(), Value::Array(ts.map(|s| Value::String(s.name().into())).into()));
        }
        if let Some(h) = self.heuristic {
            t.insert("heuristic".into(), Value::String(h.name().into()));
        }
        if let Some(n) = self.samples {
            t.insert("samples".into(), Value::Array(n.map(|n| Value::Integer(n as i64)).into()));
        }
        Value::Table(t)
    }

    fn on(&self, m: MisSettings) -> MisSettings {
        MisSettings {
            techniques: self.techniques.unwrap_or(m.techniques),
            heuristic: self.heuristic.unwrap_or(m.heuristic),
            samples: self.samples.unwrap_or(m.samples),
        }
    }
}

fn table<'a>(v: &'a Value, shape: &str) -> Result<&'a Table, String> {
    v.as_table().ok_or_else(|| format!("expected a table {shape}, found {}", v.type_str()))
}

impl Step {
    /// Whether this step sets `field` (a tour file's name for it).
    pub fn names(&self, field: &str) -> bool {
        match field {
            "scene" => self.scene.is_some(),
            "camera" => self.camera.is_some(),
            "material" => !self.materials.is_empty(),
            "probe" => self.probe.is_some(),
            "resolution" => self.resolution.is_some(),
            _ => false,
        }
    }

    /// This step followed by `later`: what `later` names wins. A step that opens another scene drops the camera,
    /// materials and probe pixel of the steps before it (they belong to the other scene). The caption is
    /// `later`'s.
    pub fn then(&self, later: &Step) -> Step {
        let other_scene = later.scene.is_some() && later.scene != self.scene;
        let earlier = |keep: bool| keep && !other_scene;
        let mut materials = if earlier(true) { self.materials.clone() } else { Vec::new() };
        materials.extend(later.materials.iter().cloned());
        Step {
            caption: later.caption.clone(),
            scene: later.scene.clone().or_else(|| self.scene.clone()),
            strategy: later.strategy.or(self.strategy),
            compare: later.compare.or(self.compare),
            budget: later.budget.or(self.budget),
            view: later.view.or(self.view),
            exposure: later.exposure.or(self.exposure),
            camera: match (self.camera.filter(|_| earlier(true)), later.camera) {
                (Some(a), Some(b)) => Some(CameraStep {
                    eye: b.eye.or(a.eye),
                    target: b.target.or(a.target),
                    up: b.up.or(a.up),
                    fov_y: b.fov_y.or(a.fov_y),
                }),
                (a, b) => b.or(a),
            },
            resolution: later.resolution.or(self.resolution),
            probe: later.probe.or(if earlier(true) { self.probe } else { Some(None) }),
            layers: later.layers.or(self.layers),
            target_spp: later.target_spp.or(self.target_spp),
            light_selection: later.light_selection.or(self.light_selection),
            footprint: later.footprint.or(self.footprint),
            seed: later.seed.or(self.seed),
            mis: match (self.mis, later.mis) {
                (Some(a), Some(b)) => Some(MisStep {
                    techniques: b.techniques.or(a.techniques),
                    heuristic: b.heuristic.or(a.heuristic),
                    samples: b.samples.or(a.samples),
                }),
                (a, b) => b.or(a),
            },
            materials,
        }
    }

    /// Sets the session to this step: what the step names changes, everything else stays. A scene other than
    /// the session's is loaded here (bundled scenes take milliseconds). The error names the field.
    pub fn apply(&self, s: &mut Session) -> Result<(), (&'static str, String)> {
        if let Some(scene) = &self.scene {
            if scene != s.source() {
                let loaded = load_scene(scene).map_err(|e| ("scene", e.to_string()))?;
                s.set_scene(loaded, scene.clone());
            }
            // The scene as its file has it, but for what the step names (a step shows the same however reached).
            if self.camera.is_none() {
                s.reset_camera();
            }
            for (i, home) in s.home_materials().to_vec().into_iter().enumerate() {
                let named =
                    s.scene().material_names.get(i).is_some_and(|n| self.materials.iter().any(|m| m.name == *n));
                if !named {
                    s.set_material(i, home);
                }
            }
        }
        if let Some(r) = self.resolution {
            s.set_resolution(r);
        }
        if let Some(c) = &self.camera {
            let camera = c.on(s.camera());
            camera.validate().map_err(|e| ("camera", e.to_string()))?;
            s.set_camera(camera);
        }
        for m in &self.materials {
            let scene = s.scene();
            let index = scene.material_names.iter().position(|n| *n == m.name).ok_or_else(|| {
                (
                    "material",
                    format!("the scene has no material `{}` (it has: {})", m.name, scene.material_names.join(", ")),
                )
            })?;
            let mut material = scene.materials[index];
            material.kd = m.kd.map_or(material.kd, vec3);
            material.ks = m.ks.map_or(material.ks, vec3);
            material.alpha = m.alpha.unwrap_or(material.alpha);
            s.set_material(index, material);
        }
        let a = s.settings();
        s.set_settings(RenderSettings {
            strategy: self.strategy.unwrap_or(a.strategy),
            light_selection: self.light_selection.unwrap_or(a.light_selection),
            seed: self.seed.unwrap_or(a.seed),
            mis: self.mis.map_or(a.mis, |m| m.on(a.mis)),
            footprint: self.footprint.unwrap_or(a.footprint),
            guiding: a.guiding,
        });
        match self.compare {
            Some(Some(b)) => s.compare_with(b),
            Some(None) => s.set_comparing(false),
            None => {}
        }
        if let Some(b) = self.budget {
            s.set_budget(b);
        }
        if let Some(v) = self.view {
            s.set_view(v);
        }
        if let Some(e) = self.exposure {
            s.set_exposure(e);
        }
        if let Some(n) = self.target_spp {
            s.set_sampling(s.pass_size(), n);
        }
        if let Some(p) = self.probe {
            let c = s.camera();
            if let Some((x, y)) = p
                && (x >= c.width || y >= c.height)
            {
                return Err(("probe", format!("pixel {x},{y} is outside the {}×{} image", c.width, c.height)));
            }
            s.set_probe_pixel(p);
        }
        if let Some(layers) = self.layers {
            s.set_probe_options(crate::session::ProbeOptions { layers, ..s.probe_options() });
        }
        Ok(())
    }

    /// Everything the session shows, as a step with `caption`: applied to any session it gives this view back.
    pub fn from_session(s: &Session, caption: Caption) -> Step {
        let camera = s.camera();
        let a = s.settings();
        let scene = s.scene();
        let materials = scene
            .materials
            .iter()
            .zip(s.home_materials())
            .enumerate()
            .filter(|(_, (now, home))| now != home)
            .map(|(i, (m, _))| MaterialStep {
                name: scene.material_names.get(i).cloned().unwrap_or_default(),
                kd: Some(m.kd.to_array()),
                ks: Some(m.ks.to_array()),
                alpha: Some(m.alpha),
            })
            .filter(|m| !m.name.is_empty())
            .collect();
        Step {
            caption,
            scene: Some(absolute_unless_bundled(s.source())),
            strategy: Some(a.strategy),
            compare: Some(s.is_comparing().then_some(s.settings_b().strategy)),
            budget: Some(s.budget()),
            view: Some(s.view()),
            exposure: Some(s.exposure()),
            camera: Some(CameraStep {
                eye: Some(camera.eye.to_array()),
                target: Some(camera.target.to_array()),
                up: Some(camera.up.to_array()),
                fov_y: Some(camera.fov_y),
            }),
            resolution: Some(camera.width.max(camera.height)),
            probe: Some(s.probe_pixel()),
            layers: s.probe_pixel().map(|_| s.probe_options().layers),
            target_spp: Some(s.target_spp()),
            light_selection: Some(a.light_selection),
            footprint: Some(a.footprint),
            seed: Some(a.seed),
            mis: Some(MisStep {
                techniques: Some(a.mis.techniques),
                heuristic: Some(a.mis.heuristic),
                samples: Some(a.mis.samples),
            }),
            materials,
        }
    }
}

/// A scene file's absolute path (a saved step loads from any tour file's folder); a bundled scene's name as it is.
fn absolute_unless_bundled(source: &str) -> String {
    if crate::scene::BUNDLED_SCENES.iter().any(|b| b.name == source) {
        return source.to_string();
    }
    std::path::absolute(source).map_or_else(|_| source.to_string(), |p| p.to_string_lossy().into_owned())
}
