//! MTL files as exporters write them (Blender, 3ds Max, the classic scene archives), read into what the Phong
//! model uses: `newmtl`, `Kd` (k_d), `Ks` (k_s), `Ns` (α) and `Ke` (L_e). Read leniently, as other tools read
//! them: a comment after the values (`Kd 0.8 0.8 0.8 # white`), a one-number colour (`Kd 0.5`, grey by the
//! format's definition), tabs, CRLF line ends, blank lines and keywords in any case. Every other statement
//! (`Ka`, `Ni`, `d`, `Tr`, `Tf`, `illum`, textures `map_*`, `bump`, PBR extensions, anything unknown) is
//! ignored — the model has no textures and no transparency — and named, once per file, in [`CleanMtl::ignored`].
//! A value that is not a number fails, naming the line and the statement.
//!
//! The result is the same file in the strict form tobj reads (three numbers per colour, no comments, nothing
//! else), so that tobj still builds the materials and their names.

/// An MTL file reduced to what the model uses.
#[derive(Debug, Default, PartialEq)]
pub struct CleanMtl {
    /// `newmtl`, `Kd`, `Ks`, `Ke` and `Ns` lines, canonical.
    pub text: String,
    /// The statements ignored, each once, in the order first met.
    pub ignored: Vec<String>,
}

/// Reduces an MTL file's text; `Err` names the line (from 1) and the statement of a malformed value.
pub fn clean_mtl(text: &str) -> Result<CleanMtl, String> {
    let mut out = CleanMtl::default();
    let mut in_material = false;
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        let at = |message: String| format!("line {}: `{line}`: {message}", i + 1);
        match keyword.to_ascii_lowercase().as_str() {
            "newmtl" => {
                let name = line[keyword.len()..].trim();
                if name.is_empty() {
                    return Err(at("newmtl needs a name".into()));
                }
                out.text.push_str(&format!("newmtl {name}\n"));
                in_material = true;
            }
            key @ ("kd" | "ks" | "ke" | "ns") if in_material => {
                let values: Vec<&str> = words.collect();
                let canonical = match key {
                    "kd" => "Kd",
                    "ks" => "Ks",
                    "ke" => "Ke",
                    _ => "Ns",
                };
                // `Kd spectral file.rfl` and `Kd xyz x y z` are other colour spaces: not the model's.
                if values.first().is_some_and(|v| v.eq_ignore_ascii_case("spectral") || v.eq_ignore_ascii_case("xyz")) {
                    note(&mut out.ignored, &format!("{canonical} {}", values[0].to_ascii_lowercase()));
                    continue;
                }
                let numbers = values
                    .iter()
                    .map(|v| v.parse::<f32>().map_err(|_| at(format!("'{v}' is not a number"))))
                    .collect::<Result<Vec<f32>, String>>()?;
                let line = match (canonical, numbers.as_slice()) {
                    ("Ns", [alpha]) => format!("Ns {alpha:?}\n"),
                    ("Ns", _) => return Err(at(format!("Ns needs one number (it has {})", numbers.len()))),
                    (_, [g]) => format!("{canonical} {g:?} {g:?} {g:?}\n"),
                    (_, [r, g, b]) => format!("{canonical} {r:?} {g:?} {b:?}\n"),
                    _ => return Err(at(format!("{canonical} needs one or three numbers (it has {})", numbers.len()))),
                };
                out.text.push_str(&line);
            }
            _ if !in_material => note(&mut out.ignored, &format!("{keyword} (before any newmtl)")),
            _ => note(&mut out.ignored, keyword),
        }
    }
    Ok(out)
}

fn note(ignored: &mut Vec<String>, what: &str) {
    if !ignored.iter().any(|w| w == what) {
        ignored.push(what.to_string());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quirks_are_read_as_their_clean_form() {
        let quirky = "# exported\r\nnewmtl white\r\n\tKd 0.8 0.8 0.8 # white\r\nKs 0.5\r\n\r\nNs 30 # shiny\r\n\
                      Ka 0.1 0.1 0.1\r\nd 1\r\nillum 2\r\nmap_Kd wood.png\r\nTr 0\r\nNi 1.45\r\nTf 1 1 1\r\n\
                      Pr 0.5\r\nnewmtl lamp\r\nke 10\r\nKD 0.1 0.2 0.3\r\n";
        let clean = clean_mtl(quirky).unwrap();
        let expected =
            "newmtl white\nKd 0.8 0.8 0.8\nKs 0.5 0.5 0.5\nNs 30.0\nnewmtl lamp\nKe 10.0 10.0 10.0\nKd 0.1 0.2 0.3\n";
        assert_eq!(clean.text, expected);
        assert_eq!(clean.ignored, ["Ka", "d", "illum", "map_Kd", "Tr", "Ni", "Tf", "Pr"]);
    }

    #[test]
    fn malformed_values_name_the_line_and_the_statement() {
        let e = clean_mtl("newmtl a\nKd 0.5 0.5 zero\n").unwrap_err();
        assert_eq!(e, "line 2: `Kd 0.5 0.5 zero`: 'zero' is not a number");
        let e = clean_mtl("newmtl a\nKs 0.5 0.5\n").unwrap_err();
        assert!(e.starts_with("line 2:") && e.contains("one or three numbers"), "{e}");
        assert!(clean_mtl("newmtl a\nNs\n").unwrap_err().contains("Ns needs one number"));
        assert!(clean_mtl("newmtl\n").unwrap_err().contains("needs a name"));
    }

    #[test]
    fn other_colour_spaces_and_stray_statements_are_named() {
        let clean = clean_mtl("Kd 1 1 1\nnewmtl a\nKd spectral x.rfl\nKs xyz 1 1 1\nfoo bar\n").unwrap();
        assert_eq!(clean.text, "newmtl a\n");
        assert_eq!(clean.ignored, ["Kd (before any newmtl)", "Kd spectral", "Ks xyz", "foo"]);
    }
}
