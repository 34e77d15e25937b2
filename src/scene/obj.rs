//! Reading an OBJ file's geometry on all cores: the `v` positions, the `f` faces as triangle fans, and the
//! statements that name objects and materials (`o`, `g`, `mtllib`, `usemtl`). The text is cut into chunks at line
//! ends and each chunk is read on its own; what depends on the lines before a chunk (the base of a relative
//! index, the materials the `mtllib` lines above a `usemtl` have loaded) is settled afterwards, in file order, so
//! the result does not depend on where the text was cut.
//!
//! It reads what tobj reads with `triangulate` (tobj still reads the MTL files, and is the oracle of the tests
//! below); one core reading with tobj took 40% of a 1M-triangle load. Where it differs, it is more lenient, and it
//! names the line of a malformed statement:
//! - texture coordinates and normals (`vt`, `vn` and a corner's `/vt/vn`) are not read: the model uses neither;
//! - a `#` starts a comment anywhere in a line (tobj fails on `v 1 2 3 # note`);
//! - a face may refer to any vertex of the file (tobj: one defined before its object ends);
//! - a name (`usemtl`, `mtllib`, `o`, `g`) is the rest of the line after the word, trimmed.

use super::SceneError;
use super::obj_cache::ObjCache;
use super::obj_words::{Words, parse_index};
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::Path;

/// A chunk is at least this many bytes: below it, a chunk's set-up costs more than reading it.
const MIN_CHUNK: usize = 1 << 16;

/// Positions are counted below 2³¹, so that a relative index pointing before the first vertex cannot wrap
/// around to a valid one (see [`Chunk::corner`]).
const MAX_POSITIONS: usize = i32::MAX as usize;

/// An OBJ file's geometry.
pub(super) struct ObjGeometry {
    /// Every `v` line's position, in file order (a fourth coordinate w divided out).
    pub positions: Vec<DVec3>,
    /// The faces' triangles in file order, the face (c₀, c₁, …, c_{n−1}) as the fan (c₀, c_i, c_{i+1}); corners
    /// index `positions`. Faces of one or two corners (points and lines) are left out.
    pub triangles: Vec<[u32; 3]>,
    /// Runs of triangles of one object and one material, in order: a run holds the triangles from its `first`
    /// up to the next run's.
    pub runs: Vec<Run>,
    /// The materials of every `mtllib` file, in the order they were loaded.
    pub materials: Vec<tobj::Material>,
    /// The names `usemtl` lines use that no material loaded above them has, each once.
    pub unknown_materials: Vec<String>,
}

#[derive(Debug)]
pub(super) struct Run {
    pub first: usize,
    pub object: String,
    /// An index into [`ObjGeometry::materials`]; `None` before any `usemtl`, or after one of an unknown name.
    pub material: Option<usize>,
}

/// A statement settled in file order, after the chunks are read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Statement<'a> {
    Object(&'a str),
    Mtllib(&'a str),
    Usemtl(&'a str),
}

/// What is known of a text of lines before they are read: whether it may hold a comment, and whether it is all
/// ASCII (its words then found byte by byte).
#[derive(Clone, Copy)]
struct Text {
    comments: bool,
    ascii: bool,
}

/// What one chunk of lines holds.
#[derive(Default)]
struct Chunk<'a> {
    /// Line ends in the chunk.
    lines: usize,
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    /// The corners (triangle × 3 + corner) given relative to the vertices above them: they hold an index from
    /// the chunk's first position, wrapped to u32, until the positions before the chunk are counted.
    relative: Vec<usize>,
    /// The statements, each with the number of the chunk's triangles above it.
    statements: Vec<(usize, Statement<'a>)>,
    /// The first malformed line: its number within the chunk (from 0) and what is wrong with it.
    error: Option<(usize, String)>,
}

/// Reads an OBJ file's text; `load_mtl` reads an `mtllib` line's file (a path relative to the OBJ's folder) and is
/// called in file order. Errors name `path`, the line and what is wrong. A large text's geometry is read back from
/// the cache the environment names ([`ObjCache`]), if it holds this text's.
pub(super) fn read_obj(
    text: &str,
    path: &Path,
    load_mtl: impl FnMut(&str) -> Result<Vec<tobj::Material>, SceneError>,
) -> Result<ObjGeometry, SceneError> {
    let parsed = match ObjCache::from_env().filter(|_| text.len() >= ObjCache::MIN_BYTES) {
        Some(cache) => {
            let key = ObjCache::key(text);
            match cache.load(key, text) {
                Some(parsed) => parsed,
                None => {
                    let parsed = parse(text, path)?;
                    // A failure to store only loses the time it would have saved.
                    let _ = cache.store(key, &parsed, text);
                    parsed
                }
            }
        }
        None => parse(text, path)?,
    };
    settle(parsed, load_mtl)
}

/// Reads the text's geometry and statements on all cores, without settling the statements.
pub(super) fn parse<'a>(text: &'a str, path: &Path) -> Result<Parsed<'a>, SceneError> {
    let size = text.len().div_ceil(4 * rayon::current_num_threads()).max(MIN_CHUNK);
    parse_in_pieces(text, path, size)
}

/// An OBJ text's geometry and its statements, before the statements are settled (the MTL files read, the runs of
/// objects and materials found).
pub(super) struct Parsed<'a> {
    /// As [`ObjGeometry`]'s.
    pub positions: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// The statements in file order, each with the number of triangles above it.
    pub statements: Vec<(usize, Statement<'a>)>,
}

/// [`read_obj`] with the text cut into pieces of about `size` bytes, and no cache.
#[cfg(test)]
fn read_in_pieces(
    text: &str,
    path: &Path,
    size: usize,
    load_mtl: impl FnMut(&str) -> Result<Vec<tobj::Material>, SceneError>,
) -> Result<ObjGeometry, SceneError> {
    settle(parse_in_pieces(text, path, size)?, load_mtl)
}

/// Reads the text cut into pieces of about `size` bytes, each on its own, then joins them.
fn parse_in_pieces<'a>(text: &'a str, path: &Path, size: usize) -> Result<Parsed<'a>, SceneError> {
    let error = |line: usize, message: String| SceneError::Obj {
        path: path.to_path_buf(),
        message: format!("line {line}: {message}"),
    };
    let pieces = cut(text, size);
    let mut chunks: Vec<Chunk> = pieces.par_iter().map(|piece| Chunk::read(piece)).collect();

    // The first line, position and triangle of each chunk.
    let mut first_line = Vec::with_capacity(chunks.len());
    let mut first_position = Vec::with_capacity(chunks.len());
    let (mut line, mut position, mut triangle) = (1, 0, 0);
    let mut statements = Vec::new();
    for chunk in &mut chunks {
        if let Some((at, message)) = &chunk.error {
            return Err(error(line + at, message.clone()));
        }
        first_line.push(line);
        first_position.push(position);
        statements.extend(chunk.statements.drain(..).map(|(at, statement)| (triangle + at, statement)));
        line += chunk.lines;
        position += chunk.positions.len();
        triangle += chunk.triangles.len();
    }
    if position > MAX_POSITIONS {
        return Err(error(line, format!("{position} vertices: at most {MAX_POSITIONS} are read")));
    }

    // The relative corners, then every corner's bounds (a corner past the last vertex names its line).
    chunks.par_iter_mut().zip(&first_position).for_each(|(chunk, &first)| {
        for &slot in &chunk.relative {
            let corner = &mut chunk.triangles[slot / 3][slot % 3];
            *corner = corner.wrapping_add(first as u32);
        }
    });
    let outside = chunks.par_iter().enumerate().find_map_first(|(c, chunk)| {
        chunk.triangles.iter().position(|t| t.iter().any(|&i| i as usize >= position)).map(|t| (c, t))
    });
    if let Some((c, t)) = outside {
        let (at, text) = line_of_triangle(pieces[c], t);
        return Err(error(
            first_line[c] + at,
            format!("'{}' refers to a vertex the file does not have (it has {position})", text.trim()),
        ));
    }
    let mut parsed =
        Parsed { positions: Vec::with_capacity(position), triangles: Vec::with_capacity(triangle), statements };
    for chunk in chunks {
        parsed.positions.extend_from_slice(&chunk.positions);
        parsed.triangles.extend_from_slice(&chunk.triangles);
    }
    Ok(parsed)
}

/// The statements in file order: the MTL files they name read through `load_mtl`, the runs of one object and
/// one material, the materials no `mtllib` above their `usemtl` defines.
pub(super) fn settle(
    parsed: Parsed,
    mut load_mtl: impl FnMut(&str) -> Result<Vec<tobj::Material>, SceneError>,
) -> Result<ObjGeometry, SceneError> {
    let mut geometry = ObjGeometry {
        positions: parsed.positions,
        triangles: parsed.triangles,
        runs: vec![Run { first: 0, object: "unnamed".into(), material: None }],
        materials: Vec::new(),
        unknown_materials: Vec::new(),
    };
    let mut material_index: HashMap<String, usize> = HashMap::new();
    for (first, statement) in parsed.statements {
        let last = geometry.runs.last().expect("a run");
        let (mut object, mut material) = (last.object.as_str(), last.material);
        match statement {
            Statement::Object(name) => object = if name.is_empty() { "unnamed" } else { name },
            Statement::Mtllib(file) => {
                for m in load_mtl(file)? {
                    material_index.insert(m.name.clone(), geometry.materials.len());
                    geometry.materials.push(m);
                }
            }
            Statement::Usemtl(name) => {
                material = material_index.get(name).copied();
                if material.is_none() && !geometry.unknown_materials.iter().any(|u| u == name) {
                    geometry.unknown_materials.push(name.to_string());
                }
            }
        }
        if (object, material) != (last.object.as_str(), last.material) {
            let run = Run { first, object: object.to_string(), material };
            match geometry.runs.last_mut() {
                Some(last) if last.first == run.first => *last = run,
                _ => geometry.runs.push(run),
            }
        }
    }
    Ok(geometry)
}

/// Cuts `text` into pieces of at least `size` bytes (but the last), each ending just after a line end (a `\n`
/// byte is never inside a multi-byte character, so the cuts fall on character boundaries).
fn cut(text: &str, size: usize) -> Vec<&str> {
    let size = size.max(1);
    let mut pieces = Vec::new();
    let mut start = 0;
    while start < text.len() {
        let end = (start + size).min(text.len());
        let end = text.as_bytes()[end..].iter().position(|&b| b == b'\n').map_or(text.len(), |i| end + i + 1);
        pieces.push(&text[start..end]);
        start = end;
    }
    pieces
}

/// The line (number within `piece`, from 0, and text) whose face made triangle `t` of the piece.
fn line_of_triangle(piece: &str, t: usize) -> (usize, &str) {
    let mut chunk = Chunk::default();
    for (at, line) in piece.split('\n').enumerate() {
        // The piece was read without error, so it reads again without one.
        let _ = chunk.read_line(line, Text { comments: true, ascii: false });
        if chunk.triangles.len() > t {
            return (at, line);
        }
    }
    unreachable!("triangle {t} is in the piece")
}

impl<'a> Chunk<'a> {
    fn read(piece: &'a str) -> Self {
        let mut chunk = Chunk::default();
        // Asked once of the piece rather than of each line (most files have neither).
        let text = Text { comments: piece.contains('#'), ascii: piece.is_ascii() };
        for (at, line) in piece.split('\n').enumerate() {
            if let Err(message) = chunk.read_line(line, text) {
                chunk.error = Some((at, format!("'{}': {message}", line.trim())));
                break;
            }
        }
        chunk.lines = piece.bytes().filter(|&b| b == b'\n').count();
        chunk
    }

    fn read_line(&mut self, line: &'a str, text: Text) -> Result<(), String> {
        let line = if text.comments { &line[..line.find('#').unwrap_or(line.len())] } else { line };
        let mut words = if text.ascii { Words::Ascii(line) } else { Words::of(line) };
        let Some(word) = words.next() else { return Ok(()) };
        // The rest of the line after the word, trimmed.
        let rest = || line.trim_start()[word.len()..].trim();
        match word {
            "v" => {
                let mut xyz = [0.0; 3];
                for x in &mut xyz {
                    *x = words.next().and_then(|w| w.parse().ok()).ok_or("a position needs three numbers")?;
                }
                let mut position = DVec3::from(xyz);
                match (words.next(), words.next(), words.next(), words.next()) {
                    (None, ..) => {}
                    (Some(w), None, ..) => {
                        let w: f64 = w.parse().map_err(|_| format!("the weight w '{w}' is not a number"))?;
                        if w == 0.0 {
                            return Err("the weight w is 0".into());
                        }
                        position /= w;
                    }
                    // A colour r g b: unused.
                    (Some(_), Some(_), Some(_), None) => {}
                    _ => return Err("a position is x y z, then a weight w or a colour r g b, or nothing".into()),
                }
                self.positions.push(position);
            }
            "f" | "l" => {
                let (mut count, mut c0, mut previous) = (0, (0, false), (0, false));
                for word in words {
                    let corner = self.corner(word)?;
                    if count >= 2 {
                        let t = self.triangles.len();
                        for (k, (_, relative)) in [c0, previous, corner].into_iter().enumerate() {
                            if relative {
                                self.relative.push(3 * t + k);
                            }
                        }
                        self.triangles.push([c0.0, previous.0, corner.0]);
                    } else if count == 0 {
                        c0 = corner;
                    }
                    previous = corner;
                    count += 1;
                }
                if count == 0 {
                    return Err("a face without corners".into());
                }
            }
            "o" | "g" => self.statements.push((self.triangles.len(), Statement::Object(rest()))),
            "mtllib" if rest().is_empty() => return Err("mtllib names no file".into()),
            "mtllib" => self.statements.push((self.triangles.len(), Statement::Mtllib(rest()))),
            "usemtl" if rest().is_empty() => return Err("usemtl names no material".into()),
            "usemtl" => self.statements.push((self.triangles.len(), Statement::Usemtl(rest()))),
            _ => {}
        }
        Ok(())
    }

    /// A face corner `v`, `v/vt`, `v//vn` or `v/vt/vn`: its vertex index from 0, and whether it is relative (a
    /// negative `v`: −1 is the last vertex above the line), in which case it counts from the chunk's first vertex
    /// and is wrapped to u32. An index past the vertices is caught once they are all counted: it is held as one
    /// at or above 2³¹ ([`MAX_POSITIONS`]).
    fn corner(&self, word: &str) -> Result<(u32, bool), String> {
        let malformed = || format!("'{word}' is not a face corner (v, v/vt, v//vn or v/vt/vn, integers)");
        let mut parts = word.as_bytes().split(|&b| b == b'/');
        let v = parts.next().and_then(parse_index).ok_or_else(malformed)?;
        // The texture coordinate's and the normal's indices: integers or nothing, and unused.
        for (k, part) in parts.enumerate() {
            if k >= 2 || !(part.is_empty() || parse_index(part).is_some()) {
                return Err(malformed());
            }
        }
        match v {
            0 => Err("vertex index 0 (indices count from 1)".into()),
            1.. => Ok((u32::try_from(v - 1).unwrap_or(u32::MAX), false)),
            _ => {
                let from_chunk = self.positions.len() as i64 + v;
                // Below −2³¹ it is before the file's first vertex whatever the chunk's place.
                let from_chunk = from_chunk.max(i32::MIN as i64);
                Ok((from_chunk as u32, true))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The triangles' corner positions and each triangle's material name, as tobj reads them.
    fn by_tobj(text: &str, mtl: &str) -> Vec<([[f64; 3]; 3], Option<String>)> {
        let options =
            tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
        let (models, materials) =
            tobj::load_obj_buf(&mut text.as_bytes(), &options, |_| tobj::load_mtl_buf(&mut mtl.as_bytes())).unwrap();
        let materials = materials.unwrap();
        let mut out = Vec::new();
        for model in models {
            let m = &model.mesh;
            let p = |i: u32| [0, 1, 2].map(|k| m.positions[3 * i as usize + k]);
            for f in m.indices.chunks_exact(3) {
                out.push(([p(f[0]), p(f[1]), p(f[2])], m.material_id.map(|i| materials[i].name.clone())));
            }
        }
        out
    }

    /// The same, as [`read_obj`] reads them with the text cut into pieces of about `size` bytes.
    fn by_chunks(text: &str, mtl: &str, size: usize) -> Vec<([[f64; 3]; 3], Option<String>)> {
        let materials =
            || tobj::load_mtl_buf(&mut mtl.as_bytes()).map(|m| m.0).map_err(|e| SceneError::Invalid(e.to_string()));
        let geometry = read_chunked(text, size, |_| materials()).unwrap();
        let mut out = Vec::new();
        for (r, run) in geometry.runs.iter().enumerate() {
            let end = geometry.runs.get(r + 1).map_or(geometry.triangles.len(), |next| next.first);
            for t in &geometry.triangles[run.first..end] {
                let material = run.material.map(|i| geometry.materials[i].name.clone());
                out.push((t.map(|i| geometry.positions[i as usize].to_array()), material));
            }
        }
        out
    }

    fn read_chunked(
        text: &str,
        size: usize,
        load_mtl: impl FnMut(&str) -> Result<Vec<tobj::Material>, SceneError>,
    ) -> Result<ObjGeometry, SceneError> {
        read_in_pieces(text, Path::new("t.obj"), size, load_mtl)
    }

    const MTL: &str = "newmtl red\nKd 1 0 0\nnewmtl white\nKd 1 1 1\n";

    /// Quirks that both readers accept: polygons, relative indices, corners with vt and vn, w, colours, objects
    /// and groups, material switches, a material used before its `mtllib`, CRLF line ends, tabs, blank lines, points
    /// and lines. (Not colours: tobj fails on a file where some vertices have one and others not.)
    const QUIRKS: &str = "# a file\r\n\
        v 0 0 0\r\n\
        v 1 0 0\r\n\
        v 1 1 0 2\r\n\
        v 0 1 0\r\n\
        usemtl red\r\n\
        mtllib scene.mtl\r\n\
        vt 0 0\nvt 1 0\nvn 0 0 1\n\
        f 1 2 3\n\
        o second\n\
        f 1/1 2/2 3/1 4/2\n\
        \n\
        usemtl white\n\
        g  group  one \n\
        v\t2 2 2\n\
        v 3 2 2\n\
        v 3 3 2\n\
        f -3//1 -2//1 -1//1\n\
        s 1\n\
        f 5/1/1 6/2/1 7/1/1 1/1/1 2/1/1\n\
        usemtl red\n\
        f 2 3 4\n\
        l 1 2\n\
        f 4\n\
        usemtl white\n\
        usemtl red\n\
        f 1 -1 -2";

    #[test]
    fn reads_what_tobj_reads_wherever_the_text_is_cut() {
        let expected = by_tobj(QUIRKS, MTL);
        assert_eq!(expected.len(), 9, "the quirks' triangles");
        for size in 1..QUIRKS.len() + 2 {
            assert_eq!(by_chunks(QUIRKS, MTL, size), expected, "pieces of {size} bytes");
        }
    }

    #[test]
    fn reads_the_bundled_meshes_and_the_knot_as_tobj_does() {
        let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
        let scenes = crate::scene::bundled::BUNDLED_SCENES.iter().map(|b| b.name).chain(["knot-box"]);
        for scene in scenes {
            let read = |ext: &str| std::fs::read_to_string(assets.join(scene).join(format!("{scene}.{ext}"))).unwrap();
            let (obj, mtl) = (read("obj"), read("mtl"));
            let expected = by_tobj(&obj, &mtl);
            assert!(!expected.is_empty());
            for size in [MIN_CHUNK, 4096, 97] {
                assert!(by_chunks(&obj, &mtl, size) == expected, "{scene}, pieces of {size} bytes");
            }
        }
    }

    fn error(text: &str, size: usize) -> String {
        match read_chunked(text, size, |_| Ok(Vec::new())) {
            Ok(_) => panic!("{text:?} reads"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn a_malformed_line_is_named_wherever_the_text_is_cut() {
        let good = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
        for (bad, says) in [
            ("v 1 2 x", "three numbers"),
            ("v 1 2 3 0", "w is 0"),
            ("v 1 2 3 4 5", "colour"),
            ("f 1 2 3/4/5/6", "not a face corner"),
            ("f 1 2 x", "not a face corner"),
            ("f 1 2 0", "index 0"),
            ("f", "without corners"),
            ("usemtl", "names no material"),
            ("mtllib  # none", "names no file"),
            ("f 1 2 99", "does not have (it has 9)"),
            ("f 1 2 -7", "does not have"),
            ("f 1 2 -9999999999", "does not have"),
            ("f 1 2 4294967297", "does not have"),
        ] {
            let text = format!("{good}{good}{bad}\n{good}");
            for size in [1, 5, 17, 1000] {
                let e = error(&text, size);
                assert!(
                    e.contains("t.obj: line 9: ") && e.contains(bad.trim()) && e.contains(says),
                    "{bad} in pieces of {size}: {e}"
                );
            }
        }
    }

    #[test]
    fn unknown_materials_are_those_no_mtllib_above_defines() {
        let text = "usemtl red\nmtllib a.mtl\nusemtl red\nusemtl  blue # a comment\nusemtl gold\nusemtl blue\n";
        let g = read_chunked(text, 3, |_| Ok(tobj::load_mtl_buf(&mut MTL.as_bytes()).unwrap().0)).unwrap();
        assert_eq!(g.unknown_materials, ["red", "blue", "gold"]);
    }

    #[test]
    fn relative_and_absolute_corners_meet_across_cuts() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nf -4 2 -2\nf 1 -3 3\n";
        for size in 1..text.len() {
            let g = read_chunked(text, size, |_| Ok(Vec::new())).unwrap();
            assert_eq!(g.triangles, [[0, 1, 2], [0, 1, 2]], "pieces of {size}");
        }
    }

    #[test]
    fn cuts_fall_after_line_ends_and_cover_the_text() {
        let text = "v 1 2 3\n\nf 1 2 3\né ü\nlast";
        for size in 0..40 {
            let pieces = cut(text, size);
            assert_eq!(pieces.concat(), text);
            assert!(pieces[..pieces.len() - 1].iter().all(|p| p.ends_with('\n')));
        }
    }
}
