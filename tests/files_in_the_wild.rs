//! Files as exporters write them: each quirk of real OBJ/MTL files loads, and renders the same film, bit for bit,
//! as the clean file; what the model ignores is named in one warning line per file; a missing MTL file or an
//! unknown material is a warning and the default grey, not a failure; a malformed number still fails, naming the
//! file, the line and the statement.

mod common;

use illumlab::render::{Film, RenderSettings, Renderer, Strategy};
use illumlab::scene::{Scene, load_scene_file};
use std::fs;
use std::sync::Arc;
use tempfile::TempDir;

use common::SMALL_SCENE_TOML as TOML;

/// A glossy floor quad under a square light, in the clean form.
const OBJ: &str = "\
mtllib scene.mtl
v -1.0 0.0 1.0
v 1.0 0.0 1.0
v 1.0 0.0 -1.0
v -1.0 0.0 -1.0
v -0.25 1.5 -0.25
v 0.25 1.5 -0.25
v 0.25 1.5 0.25
v -0.25 1.5 0.25
usemtl grey
f 1 2 3
f 1 3 4
usemtl light
f 5 6 7
f 5 7 8
";

const MTL: &str = "\
newmtl grey
Kd 0.5 0.5 0.5
Ks 0.25 0.25 0.25
Ns 20.0
newmtl light
Kd 0.0 0.0 0.0
Ke 10.0 10.0 10.0
";

fn load(obj: &str, mtl: Option<&str>) -> (TempDir, Result<Scene, String>) {
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("scene.toml"), TOML).unwrap();
    fs::write(dir.path().join("scene.obj"), obj).unwrap();
    if let Some(mtl) = mtl {
        fs::write(dir.path().join("scene.mtl"), mtl).unwrap();
    }
    let scene = load_scene_file(&dir.path().join("scene.toml")).map_err(|e| e.to_string());
    (dir, scene)
}

fn film(scene: Scene) -> Vec<[f32; 3]> {
    let settings = RenderSettings { strategy: Strategy::Mis, ..Default::default() };
    let (w, h) = (scene.camera.width, scene.camera.height);
    let mut renderer = Renderer::new(Arc::new(scene), settings);
    let mut film = Film::new(w, h);
    renderer.render_pass(&mut film, 0, 4, &|| false);
    film.means().iter().map(|v| v.to_array()).collect()
}

/// Loads the variant, checks it renders the clean file's film bit for bit, and returns its warnings.
fn same_film_as_clean(obj: &str, mtl: &str) -> Vec<String> {
    let (_dir, clean) = load(OBJ, Some(MTL));
    let clean = clean.expect("the clean scene loads");
    assert!(clean.warnings.is_empty(), "the clean scene warns: {:?}", clean.warnings);
    let (_dir2, variant) = load(obj, Some(mtl));
    let variant = variant.unwrap_or_else(|e| panic!("the variant does not load: {e}"));
    let warnings = variant.warnings.clone();
    let reference = film(clean);
    assert!(reference.iter().flatten().any(|&v| v > 0.0), "the clean film is black: the comparison would say nothing");
    assert_eq!(film(variant), reference, "the variant renders another film");
    warnings
}

fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "fixture edit: {from:?} not found");
    text.replace(from, to)
}

#[test]
fn a_comment_after_the_values() {
    let mtl = edit(MTL, "Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5 # grey");
    assert!(same_film_as_clean(OBJ, &mtl).is_empty());
}

#[test]
fn a_changed_material_changes_the_film() {
    // The comparison has power: a variant that is not the same scene fails it.
    let mtl = edit(MTL, "Kd 0.5 0.5 0.5", "Kd 0.4 0.5 0.5");
    let result = std::panic::catch_unwind(|| same_film_as_clean(OBJ, &mtl));
    assert!(result.is_err(), "a different k_d rendered the same film");
}

#[test]
fn a_one_number_colour_is_grey() {
    let mtl = edit(&edit(MTL, "Kd 0.5 0.5 0.5", "Kd 0.5"), "Ke 10.0 10.0 10.0", "Ke 10");
    assert!(same_film_as_clean(OBJ, &mtl).is_empty());
}

#[test]
fn tabs_crlf_and_blank_lines() {
    let mtl = MTL.replace(' ', "\t").replace('\n', "\r\n\r\n");
    let obj = OBJ.replace(' ', " \t ").replace('\n', "\r\n");
    assert!(same_film_as_clean(&obj, &mtl).is_empty());
}

#[test]
fn what_the_model_ignores_is_named_once_per_file() {
    let extra =
        "Ka 0.1 0.1 0.1\nNi 1.45\nd 1.0\nTr 0.0\nTf 1 1 1\nillum 2\nmap_Kd wood.png\nbump -bm 0.5 b.png\nPr 0.4\n";
    let mtl = edit(MTL, "Ns 20.0\n", &format!("Ns 20.0\n{extra}"));
    let mtl = edit(&mtl, "Ke 10.0 10.0 10.0\n", &format!("Ke 10.0 10.0 10.0\n{extra}"));
    let warnings = same_film_as_clean(OBJ, &mtl);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = &warnings[0];
    assert!(w.contains("scene.mtl") && w.contains("ignored"), "{w}");
    let named: Vec<&str> = w.rsplit(": ").next().unwrap().split(", ").collect();
    assert_eq!(named, ["Ka", "Ni", "d", "Tr", "Tf", "illum", "map_Kd", "bump", "Pr"], "{w}");
}

#[test]
fn unknown_statements_are_named() {
    let mtl = edit(MTL, "Ns 20.0\n", "Ns 20.0\nsharpness 60\nfoo bar\n");
    let warnings = same_film_as_clean(OBJ, &mtl);
    assert!(warnings.len() == 1 && warnings[0].contains("sharpness, foo"), "{warnings:?}");
}

#[test]
fn a_missing_mtl_file_is_a_warning_and_the_default_grey() {
    let (_dir, scene) = load(OBJ, None);
    let scene = scene.expect("loads without its MTL");
    let w = scene.warnings.join("\n");
    assert!(w.contains("scene.mtl") && w.contains("no such MTL file") && w.contains("default grey"), "{w}");
    assert!(w.contains("usemtl") && w.contains("grey, light"), "the unknown materials are named: {w}");
    assert!(scene.materials.iter().all(|m| m.kd == glam::Vec3::splat(0.5)), "the default material");
}

#[test]
fn an_unknown_material_is_a_warning_and_the_default_grey() {
    let obj = edit(OBJ, "usemtl grey", "usemtl marble");
    let (_dir, scene) = load(&obj, Some(MTL));
    let scene = scene.expect("loads");
    let w = scene.warnings.join("\n");
    assert!(w.contains("marble") && w.contains("default grey"), "{w}");
}

#[test]
fn a_malformed_number_fails_naming_the_file_line_and_statement() {
    let mtl = edit(MTL, "Ns 20.0", "Ns twenty");
    let (_dir, scene) = load(OBJ, Some(&mtl));
    let Err(e) = scene else { panic!("a malformed number fails") };
    assert!(e.contains("scene.mtl") && e.contains("line 4") && e.contains("Ns twenty"), "{e}");
    assert_eq!(e.lines().count(), 1, "one line: {e}");
}

#[test]
fn polygons_with_more_than_three_vertices_are_triangulated() {
    let obj = edit(&edit(OBJ, "f 1 2 3\nf 1 3 4", "f 1 2 3 4"), "f 5 6 7\nf 5 7 8", "f 5 6 7 8");
    assert!(same_film_as_clean(&obj, MTL).is_empty());
}

#[test]
fn negative_indices_count_back_from_the_last_vertex() {
    let obj =
        edit(&edit(OBJ, "f 5 6 7\nf 5 7 8", "f -4 -3 -2\nf -4 -2 -1"), "f 1 2 3\nf 1 3 4", "f -8 -7 -6\nf -8 -6 -5");
    assert!(same_film_as_clean(&obj, MTL).is_empty());
}

#[test]
fn object_group_and_smoothing_lines() {
    let obj = edit(
        &edit(OBJ, "usemtl grey", "o floor\ng floor_group\ns 1\nusemtl grey"),
        "usemtl light",
        "o lamp\ns off\nusemtl light",
    );
    assert!(same_film_as_clean(&obj, MTL).is_empty());
}

#[test]
fn normals_and_texture_coordinates_are_loaded_and_unused() {
    let mut obj = edit(OBJ, "usemtl grey", "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 1 0\nusemtl grey");
    obj = edit(&obj, "f 1 2 3\nf 1 3 4", "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/2/1");
    obj = edit(&obj, "f 5 6 7\nf 5 7 8", "f 5//1 6//1 7//1\nf 5//1 7//1 8//1");
    assert!(same_film_as_clean(&obj, MTL).is_empty());
}

#[test]
fn the_bundled_scenes_load_without_warnings_from_the_loader() {
    for name in ["cornell-box", "veach-mis", "near-light", "occluded-light", "default"] {
        let scene = illumlab::scene::load_scene(name).unwrap();
        assert!(
            scene.warnings.iter().all(|w| !w.contains("ignored") && !w.contains("MTL")),
            "{name}: {:?}",
            scene.warnings
        );
    }
}
