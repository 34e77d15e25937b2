//! Tour files: TOML read field by field, so that every error names its step and its field, and steps written back
//! (the viewer's "save this view as a step").

use super::step::{CameraStep, MaterialStep, MisStep};
use super::{Caption, LAYER_NAMES, Step, Tour, layer_names, layers_from_names};
use crate::render::{Footprint, Heuristic, Strategy};
use crate::scene::LightSelection;
use crate::session::views::View;
use crate::session::worker::Budget;
use toml::{Table, Value};

/// What is wrong with a tour, and where: the file, the step (1-based, with its title) and the field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {}{problem}", where_(.step, .field))]
pub struct TourError {
    pub file: String,
    pub step: Option<(usize, String)>,
    pub field: Option<String>,
    pub problem: String,
}

fn where_(step: &Option<(usize, String)>, field: &Option<String>) -> String {
    let mut s = String::new();
    if let Some((n, title)) = step {
        s += &format!("step {n}");
        if !title.is_empty() {
            s += &format!(" (\"{title}\")");
        }
    }
    if let Some(f) = field {
        s += &format!("{}field `{f}`", if s.is_empty() { "" } else { ", " });
    }
    if !s.is_empty() {
        s += ": ";
    }
    s
}

impl TourError {
    pub fn new(file: &str, step: Option<(usize, String)>, field: Option<&str>, problem: impl Into<String>) -> Self {
        Self { file: file.into(), step, field: field.map(Into::into), problem: problem.into() }
    }
}

/// The fields a step may have, in the order a saved step writes them.
const STEP_FIELDS: [&str; 19] = [
    "title",
    "formula",
    "caption",
    "scene",
    "resolution",
    "camera",
    "material",
    "strategy",
    "light_selection",
    "mis",
    "seed",
    "footprint",
    "compare",
    "budget",
    "view",
    "exposure",
    "target_spp",
    "probe",
    "layers",
];

/// Parses a tour; `file` names it in errors.
pub fn parse_tour(text: &str, file: &str) -> Result<Tour, TourError> {
    let table: Table = text.parse().map_err(|e: toml::de::Error| {
        TourError::new(file, None, None, format!("not valid TOML: {}", e.message().trim())).with_line(text, e.span())
    })?;
    let mut title = String::new();
    let mut steps = Vec::new();
    for (key, value) in &table {
        match key.as_str() {
            "title" => title = string(value).map_err(|p| TourError::new(file, None, Some("title"), p))?,
            "step" => {
                let Value::Array(items) = value else {
                    return Err(TourError::new(file, None, Some("step"), "expected [[step]] tables"));
                };
                for (i, item) in items.iter().enumerate() {
                    let Value::Table(t) = item else {
                        return Err(TourError::new(file, Some((i + 1, String::new())), None, "expected a table"));
                    };
                    steps.push(parse_step(t, i + 1, file)?);
                }
            }
            other => {
                return Err(TourError::new(file, None, Some(other), "unknown field (a tour has `title` and [[step]])"));
            }
        }
    }
    if steps.is_empty() {
        return Err(TourError::new(file, None, None, "no steps: add [[step]] tables"));
    }
    Ok(Tour { file: file.to_string(), title, steps })
}

impl TourError {
    /// Adds the line of a TOML syntax error.
    fn with_line(mut self, text: &str, span: Option<std::ops::Range<usize>>) -> Self {
        if let Some(span) = span {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            self.problem = format!("line {line}: {}", self.problem);
        }
        self
    }
}

fn parse_step(t: &Table, n: usize, file: &str) -> Result<Step, TourError> {
    let title = t.get("title").and_then(Value::as_str).unwrap_or_default().to_string();
    let err = |field: &str, problem: String| TourError::new(file, Some((n, title.clone())), Some(field), problem);
    let mut step = Step::default();
    for (key, value) in t {
        let field = key.as_str();
        let fail = |p: String| err(field, p);
        match field {
            "title" => step.caption.title = string(value).map_err(fail)?,
            "formula" => step.caption.formula = string(value).map_err(fail)?,
            "caption" => step.caption.text = string(value).map_err(fail)?,
            "scene" => step.scene = Some(string(value).map_err(fail)?),
            "strategy" => step.strategy = Some(strategy(value).map_err(fail)?),
            "compare" => {
                let s = string(value).map_err(fail)?;
                step.compare = Some(if s == "off" { None } else { Some(strategy(value).map_err(fail)?) });
            }
            "budget" => {
                let s = string(value).map_err(fail)?;
                let b = Budget::from_slug(&s)
                    .ok_or_else(|| fail(unknown("budget", &s, &["equal-samples", "equal-time"])))?;
                step.budget = Some(b);
            }
            "view" => {
                let s = string(value).map_err(fail)?;
                let names: Vec<&str> = View::ALL.iter().map(|v| v.slug()).collect();
                step.view = Some(View::from_slug(&s).ok_or_else(|| fail(unknown("view", &s, &names)))?);
            }
            "exposure" => step.exposure = Some(number(value, -20.0, 20.0).map_err(fail)? as f32),
            "resolution" => step.resolution = Some(whole(value, 1, 16384).map_err(fail)? as u32),
            "target_spp" => {
                step.target_spp = Some(match value {
                    Value::String(s) if s == "off" => None,
                    _ => Some(whole(value, 1, 1_000_000).map_err(|p| fail(format!("{p} (or \"off\")")))? as u32),
                })
            }
            "seed" => step.seed = Some(whole(value, 0, i64::MAX).map_err(fail)? as u64),
            "camera" => step.camera = Some(CameraStep::parse(value).map_err(fail)?),
            "probe" => {
                step.probe = Some(match value {
                    Value::String(s) if s == "off" => None,
                    Value::Array(a) if a.len() == 2 => {
                        let x = whole(&a[0], 0, 16383).map_err(fail)? as u32;
                        Some((x, whole(&a[1], 0, 16383).map_err(fail)? as u32))
                    }
                    _ => return Err(fail("expected [x, y] (a pixel) or \"off\"".into())),
                })
            }
            "layers" => {
                let Value::Array(a) = value else {
                    return Err(fail(format!("expected a list of {}", LAYER_NAMES.join(", "))));
                };
                let mut names = Vec::new();
                for v in a {
                    let s = string(v).map_err(fail)?;
                    let known = LAYER_NAMES
                        .iter()
                        .find(|n| **n == s)
                        .ok_or_else(|| fail(unknown("layer", &s, &LAYER_NAMES)))?;
                    names.push(*known);
                }
                step.layers = Some(layers_from_names(&names));
            }
            "light_selection" => {
                let s = string(value).map_err(fail)?;
                let names: Vec<&str> = LightSelection::ALL.iter().map(|l| l.name()).collect();
                step.light_selection =
                    Some(LightSelection::from_name(&s).ok_or_else(|| fail(unknown("light selection", &s, &names)))?);
            }
            "footprint" => {
                let s = string(value).map_err(fail)?;
                step.footprint = Some(
                    Footprint::from_name(&s).ok_or_else(|| fail(unknown("footprint", &s, &["jittered", "centre"])))?,
                );
            }
            "mis" => step.mis = Some(MisStep::parse(value).map_err(fail)?),
            "material" => {
                let Value::Array(a) = value else { return Err(fail("expected [[step.material]] tables".into())) };
                for m in a {
                    step.materials.push(MaterialStep::parse(m).map_err(fail)?);
                }
            }
            _ => return Err(fail(format!("unknown field (a step may have: {})", STEP_FIELDS.join(", ")))),
        }
    }
    Ok(step)
}

fn unknown(what: &str, value: &str, names: &[&str]) -> String {
    format!("unknown {what} `{value}` (one of: {})", names.join(", "))
}

pub(super) fn string(v: &Value) -> Result<String, String> {
    v.as_str().map(str::to_string).ok_or_else(|| format!("expected a string, found {}", kind(v)))
}

pub(super) fn strategy(v: &Value) -> Result<Strategy, String> {
    let s = string(v)?;
    let names: Vec<&str> = Strategy::ALL.iter().map(|s| s.name()).collect();
    Strategy::from_name(&s).ok_or_else(|| unknown("strategy", &s, &names))
}

pub(super) fn heuristic(v: &Value) -> Result<Heuristic, String> {
    let s = string(v)?;
    Heuristic::from_name(&s).ok_or_else(|| unknown("heuristic", &s, &["balance", "power"]))
}

/// A number (integer or float) within [lo, hi].
pub(super) fn number(v: &Value, lo: f64, hi: f64) -> Result<f64, String> {
    let x = match v {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        _ => return Err(format!("expected a number, found {}", kind(v))),
    };
    if x.is_finite() && (lo..=hi).contains(&x) { Ok(x) } else { Err(format!("{x} is outside {lo} … {hi}")) }
}

pub(super) fn whole(v: &Value, lo: i64, hi: i64) -> Result<i64, String> {
    let Value::Integer(i) = v else { return Err(format!("expected a whole number, found {}", kind(v))) };
    if (lo..=hi).contains(i) { Ok(*i) } else { Err(format!("{i} is outside {lo} … {hi}")) }
}

pub(super) fn triple(v: &Value, lo: f64, hi: f64) -> Result<[f32; 3], String> {
    match v {
        Value::Array(a) if a.len() == 3 => {
            let mut out = [0.0; 3];
            for (o, x) in out.iter_mut().zip(a) {
                *o = number(x, lo, hi)? as f32;
            }
            Ok(out)
        }
        _ => Err(format!("expected [x, y, z], found {}", kind(v))),
    }
}

fn kind(v: &Value) -> &'static str {
    v.type_str()
}

/// The step as a `[[step]]` table of a tour file (appended by "save this view as a step").
pub fn step_toml(step: &Step) -> String {
    let mut t = Table::new();
    let s = |x: &str| Value::String(x.to_string());
    let Caption { title, formula, text } = &step.caption;
    for (k, v) in [("title", title), ("formula", formula), ("caption", text)] {
        if !v.is_empty() {
            t.insert(k.into(), s(v));
        }
    }
    if let Some(scene) = &step.scene {
        t.insert("scene".into(), s(scene));
    }
    if let Some(r) = step.resolution {
        t.insert("resolution".into(), Value::Integer(r as i64));
    }
    if let Some(c) = &step.camera {
        t.insert("camera".into(), c.to_toml());
    }
    if !step.materials.is_empty() {
        t.insert("material".into(), Value::Array(step.materials.iter().map(MaterialStep::to_toml).collect()));
    }
    if let Some(x) = step.strategy {
        t.insert("strategy".into(), s(x.name()));
    }
    if let Some(x) = step.light_selection {
        t.insert("light_selection".into(), s(x.name()));
    }
    if let Some(m) = &step.mis {
        t.insert("mis".into(), m.to_toml());
    }
    if let Some(x) = step.seed {
        t.insert("seed".into(), Value::Integer(x.min(i64::MAX as u64) as i64));
    }
    if let Some(x) = step.footprint {
        t.insert("footprint".into(), s(x.name()));
    }
    if let Some(c) = step.compare {
        t.insert("compare".into(), s(c.map_or("off", |b| b.name())));
    }
    if let Some(b) = step.budget {
        t.insert("budget".into(), s(b.slug()));
    }
    if let Some(v) = step.view {
        t.insert("view".into(), s(v.slug()));
    }
    if let Some(e) = step.exposure {
        t.insert("exposure".into(), Value::Float(e as f64));
    }
    if let Some(n) = step.target_spp {
        t.insert("target_spp".into(), n.map_or(s("off"), |n| Value::Integer(n as i64)));
    }
    if let Some(p) = step.probe {
        let v = p.map_or(s("off"), |(x, y)| Value::Array(vec![Value::Integer(x as i64), Value::Integer(y as i64)]));
        t.insert("probe".into(), v);
    }
    if let Some(l) = &step.layers {
        t.insert("layers".into(), Value::Array(layer_names(l).into_iter().map(s).collect()));
    }
    let mut doc = Table::new();
    doc.insert("step".into(), Value::Array(vec![Value::Table(t)]));
    toml::to_string(&doc).expect("a table of strings and numbers serialises")
}

/// Appends `step` to the tour file at `path` (created, with a title, if it does not exist).
pub fn append_step(path: &std::path::Path, step: &Step) -> Result<(), String> {
    use std::io::Write;
    let new = !path.exists();
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let mut text = String::new();
    if new {
        text += "title = \"My tour\"\n";
    }
    text += "\n";
    text += &step_toml(step);
    f.write_all(text.as_bytes()).map_err(|e| format!("cannot write {}: {e}", path.display()))
}
