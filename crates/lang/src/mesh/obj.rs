//! Wavefront `.obj` files, as modellers and scripts write them, read by a reader of its own.
//!
//! One pass over the statements builds the mesh and stops at the first fault, located at the
//! word to blame: a vertex that is not three finite numbers, a face of fewer than three
//! corners, a corner that is not `v`, `v/vt`, `v//vn` or `v/vt/vn`, an index that names
//! nothing defined before it. Comments (whole lines or trailing), blank lines, CRLF line
//! ends and `\` continuations are read as every exporter writes them; `o`, `g` and `s` are
//! read past; materials (`mtllib`, `usemtl`), lines and points are ignored with a note; any
//! other statement is a warning, once per keyword, with how many lines use it. Polygons are
//! split into fans of triangles, `(a, b, c)`, `(a, c, d)`, ... (as tobj, which read these
//! files before, split them). Vertices are those the faces use, in the order they first
//! appear; with normals at every corner, one vertex per position and normal pair.

use std::collections::HashMap;
use std::ops::Range;

use whitted_ir::Severity;

use super::{MeshData, MeshError, Place, Remark, VertexNumbers};

/// Statements of the OBJ format that whitted does not read: free-form geometry, and
/// rendering attributes of other programs. They are warned about as ignored, not as unknown.
const UNREAD: &[&str] = &[
    "vp",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "maplib",
    "usemap",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
];

/// How many different ignored keywords are warned about, one warning each; the rest are
/// counted in one more warning (a text that is not an OBJ file would otherwise give a
/// warning per line).
const MAX_KEYWORD_WARNINGS: usize = 10;

/// The accepted forms of a face corner, for messages.
const CORNER_FORMS: &str = "a corner is `v`, `v/vt`, `v//vn` or `v/vt/vn`, each a whole number";

/// Parses an OBJ file of at most `budget` triangles.
pub(super) fn parse(bytes: &[u8], budget: usize) -> Result<MeshData, MeshError> {
    let mut reader = Reader::default();
    let mut words: Vec<(&str, usize)> = Vec::new();
    // Where the statement being gathered starts (its first line may end in `\`).
    let mut statement_start = 0usize;
    let mut line_start = 0usize;
    for raw in bytes.split(|&b| b == b'\n') {
        let start = line_start;
        line_start += raw.len() + 1;
        let line = match std::str::from_utf8(raw) {
            Ok(line) => line,
            Err(error) => {
                return Err(MeshError::new(
                    Place::Bytes(start..start + error.valid_up_to()),
                    "this line is not UTF-8 text",
                ));
            }
        };
        if words.is_empty() {
            statement_start = start;
        }
        // A `#` starts a comment wherever it is: no word of the statements read has one.
        let content = line.split('#').next().unwrap_or("");
        let content = content.trim_end_matches(|c: char| c.is_ascii_whitespace());
        let (content, continued) = match content.strip_suffix('\\') {
            Some(rest) => (rest, true),
            None => (content, false),
        };
        words.extend(content.split_ascii_whitespace().map(|word| {
            // `word` is a slice of `line`: its offset locates it in the file.
            (
                word,
                start + (word.as_ptr() as usize - line.as_ptr() as usize),
            )
        }));
        if !continued && !words.is_empty() {
            reader.statement(&words, statement_start, budget)?;
            words.clear();
        }
    }
    if !words.is_empty() {
        reader.statement(&words, statement_start, budget)?;
    }
    Ok(reader.finish())
}

/// What the statements so far have defined.
struct Reader<'a> {
    positions: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    texcoords: usize,
    /// Three corners per triangle: (position index, normal index or `u32::MAX`).
    corners: Vec<[u32; 2]>,
    /// Per triangle, where its face statement starts in the file.
    face_starts: Vec<usize>,
    /// Whether every corner so far names a normal.
    all_normals: bool,
    /// The first `mtllib` or `usemtl`, and the first `l` or `p` with how many there are.
    materials: Option<Range<usize>>,
    lines_and_points: Option<(Range<usize>, usize)>,
    /// Statements ignored, by keyword in order of first use: (keyword, first place, count).
    ignored: Vec<(&'a str, Range<usize>, usize)>,
    ignored_index: HashMap<&'a str, usize>,
    /// Lines of keywords past [`MAX_KEYWORD_WARNINGS`], and the first place of one.
    other_ignored: Option<(Range<usize>, usize)>,
    /// The corners of the face being read.
    polygon: Vec<[u32; 2]>,
}

impl<'a> Reader<'a> {
    /// One statement: its words with their offsets in the file, and where it starts.
    fn statement(
        &mut self,
        words: &[(&'a str, usize)],
        start: usize,
        budget: usize,
    ) -> Result<(), MeshError> {
        let (keyword, at) = words[0];
        let whole = start..words.last().map_or(at, |&(w, o)| o + w.len());
        let keyword_place = at..at + keyword.len();
        match keyword {
            "v" => {
                let p = numbers(&words[1..], 3, "a vertex", &whole)?;
                let mut position = [p[0] as f32, p[1] as f32, p[2] as f32];
                // `v x y z w`: a weight divides the coordinates; more numbers are a colour.
                if let [_, _, _, _, (word, offset)] = words {
                    let w = parse_number(word).filter(|w| *w != 0.0);
                    let Some(w) = w else {
                        return Err(MeshError::new(
                            Place::Bytes(*offset..offset + word.len()),
                            format!(
                                "a vertex's weight must be a number other than 0, not `{word}`"
                            ),
                        ));
                    };
                    position = position.map(|x| (f64::from(x) / w) as f32);
                }
                if position.iter().any(|x| !x.is_finite()) {
                    return Err(MeshError::new(
                        Place::Bytes(whole),
                        "this vertex is out of range once divided by its weight",
                    ));
                }
                self.positions.push(position);
            }
            "vn" => {
                let n = numbers(&words[1..], 3, "a normal", &whole)?;
                self.normals.push([n[0] as f32, n[1] as f32, n[2] as f32]);
            }
            "vt" => {
                numbers(&words[1..], 1, "a texture coordinate", &whole)?;
                self.texcoords += 1;
            }
            "f" => self.face(&words[1..], whole, budget)?,
            "o" | "g" | "s" => {}
            "mtllib" | "usemtl" => {
                self.materials.get_or_insert(keyword_place);
            }
            "l" | "p" => {
                let (_, count) = self.lines_and_points.get_or_insert((keyword_place, 0));
                *count += 1;
            }
            _ => self.ignore(keyword, keyword_place),
        }
        Ok(())
    }

    /// A statement whitted does not read: counted under its keyword.
    fn ignore(&mut self, keyword: &'a str, place: Range<usize>) {
        if let Some(&index) = self.ignored_index.get(keyword) {
            self.ignored[index].2 += 1;
        } else if self.ignored.len() < MAX_KEYWORD_WARNINGS {
            self.ignored_index.insert(keyword, self.ignored.len());
            self.ignored.push((keyword, place, 1));
        } else {
            self.other_ignored.get_or_insert((place, 0)).1 += 1;
        }
    }

    /// `f` and its corners (`words`), the whole statement at `whole`.
    fn face(
        &mut self,
        words: &[(&str, usize)],
        whole: Range<usize>,
        budget: usize,
    ) -> Result<(), MeshError> {
        if words.len() < 3 {
            let count = match words.len() {
                0 => "none".to_string(),
                n => n.to_string(),
            };
            return Err(MeshError::new(
                Place::Bytes(whole),
                format!("a face needs three corners or more, and this one has {count}"),
            )
            .with_hint("a line is written `l`, and a point `p`; whitted ignores both"));
        }
        let triangles = self.face_starts.len().saturating_add(words.len() - 2);
        if triangles > budget {
            return Err(MeshError::too_many(triangles));
        }
        let mut polygon = std::mem::take(&mut self.polygon);
        polygon.clear();
        for &(word, offset) in words {
            let corner = self.corner(word, offset..offset + word.len())?;
            self.all_normals &= corner[1] != u32::MAX;
            polygon.push(corner);
        }
        for k in 1..polygon.len() - 1 {
            self.corners
                .extend([polygon[0], polygon[k], polygon[k + 1]]);
            self.face_starts.push(whole.start);
        }
        self.polygon = polygon;
        Ok(())
    }

    /// One corner: its position index and its normal index (`u32::MAX` for none), both
    /// from 0, checked against what is defined so far.
    fn corner(&self, word: &str, place: Range<usize>) -> Result<[u32; 2], MeshError> {
        let malformed = || {
            MeshError::new(
                Place::Bytes(place.clone()),
                format!("`{word}` is not a face corner: {CORNER_FORMS}"),
            )
            .with_hint(
                "1 is the first vertex (or texture coordinate, or normal), and -1 the latest",
            )
        };
        let mut parts = word.split('/');
        let (v, vt, vn) = match (parts.next(), parts.next(), parts.next(), parts.next()) {
            (Some(v), None, None, None) => (v, None, None),
            (Some(v), Some(vt), None, None) if !vt.is_empty() => (v, Some(vt), None),
            (Some(v), Some(vt), Some(vn), None) if !vn.is_empty() => {
                (v, (!vt.is_empty()).then_some(vt), Some(vn))
            }
            _ => return Err(malformed()),
        };
        let number = |part: &str| part.parse::<i64>().map_err(|_| malformed());
        let v = number(v)?;
        let vt = vt.map(number).transpose()?;
        let vn = vn.map(number).transpose()?;
        let position = resolve(v, self.positions.len(), 0, &place)?;
        if let Some(vt) = vt {
            resolve(vt, self.texcoords, 1, &place)?;
        }
        let normal = match vn {
            Some(vn) => resolve(vn, self.normals.len(), 2, &place)?,
            None => u32::MAX,
        };
        Ok([position, normal])
    }

    /// The mesh: the vertices the faces use, in the order of first use.
    fn finish(self) -> MeshData {
        let normals = self.all_normals && !self.corners.is_empty();
        let mut data = MeshData::default();
        let mut numbers = Vec::new();
        let mut triangles = Vec::with_capacity(self.corners.len() / 3);
        let mut id_of_position = vec![u32::MAX; self.positions.len()];
        let mut id_of_pair: HashMap<[u32; 2], u32> = HashMap::new();
        for triangle in self.corners.chunks_exact(3) {
            let mut t = [0u32; 3];
            for (id, &[p, n]) in t.iter_mut().zip(triangle) {
                let next = data.positions.len() as u32;
                let known = if normals {
                    *id_of_pair.entry([p, n]).or_insert(next)
                } else {
                    let slot = &mut id_of_position[p as usize];
                    if *slot == u32::MAX {
                        *slot = next;
                    }
                    *slot
                };
                if known == next {
                    data.positions.push(self.positions[p as usize]);
                    if normals {
                        data.normals.push(self.normals[n as usize]);
                    }
                    numbers.push(u64::from(p) + 1);
                }
                *id = known;
            }
            triangles.push(t);
        }
        data.triangles = triangles;
        data.vertex_numbers = VertexNumbers::Table(numbers);
        data.face_starts = self.face_starts;
        if let Some(place) = self.materials {
            data.remarks.push(
                Remark::new(
                    Severity::Note,
                    place,
                    "this file's materials (`mtllib`, `usemtl`) are ignored",
                )
                .with_hint(
                    "the scene gives the mesh its material: `mesh { file ... material glass }`",
                ),
            );
        }
        if let Some((place, count)) = self.lines_and_points {
            data.remarks.push(Remark::new(
                Severity::Note,
                place,
                format!(
                    "lines and points (`l`, `p`) have no surface to render; {}",
                    lines_ignored(count, "have them")
                ),
            ));
        }
        for (keyword, place, count) in self.ignored {
            let shown: String = keyword.chars().take(32).collect();
            let shown = if shown.len() < keyword.len() {
                format!("{shown}...")
            } else {
                shown
            };
            let known = if UNREAD.contains(&keyword) {
                "is an OBJ statement whitted does not read"
            } else {
                "is not an OBJ statement whitted knows"
            };
            data.remarks.push(Remark::new(
                Severity::Warning,
                place,
                format!("`{shown}` {known}; {}", lines_ignored(count, "use it")),
            ));
        }
        if let Some((place, lines)) = self.other_ignored {
            data.remarks.push(Remark::new(
                Severity::Warning,
                place,
                format!(
                    "more keywords whitted does not know; {}",
                    lines_ignored(lines, "have them")
                ),
            ));
        }
        data
    }
}

impl Default for Reader<'_> {
    fn default() -> Self {
        Reader {
            positions: Vec::new(),
            normals: Vec::new(),
            texcoords: 0,
            corners: Vec::new(),
            face_starts: Vec::new(),
            all_normals: true,
            materials: None,
            lines_and_points: None,
            ignored: Vec::new(),
            ignored_index: HashMap::new(),
            other_ignored: None,
            polygon: Vec::new(),
        }
    }
}

/// "3 lines use it (the first here), and they are ignored" (with `verb` "use it"), or for
/// one line "this line is ignored".
fn lines_ignored(count: usize, verb: &str) -> String {
    match count {
        1 => "this line is ignored".to_string(),
        n => format!("{n} lines {verb} (the first here), and they are ignored"),
    }
}

/// A number as OBJ writes it (finite or not; callers check).
fn parse_number(word: &str) -> Option<f64> {
    word.parse::<f64>().ok()
}

/// At least `count` (at most 3) finite numbers after the keyword, the first `count` of the
/// result; more are read past.
fn numbers(
    words: &[(&str, usize)],
    count: usize,
    what: &str,
    whole: &Range<usize>,
) -> Result<[f64; 3], MeshError> {
    let mut values = [0.0; 3];
    let mut found = 0;
    for &(word, offset) in words.iter().take(count.min(3)) {
        let place = Place::Bytes(offset..offset + word.len());
        match parse_number(word) {
            Some(x) if x.is_finite() && (x as f32).is_finite() => {
                values[found] = x;
                found += 1;
            }
            Some(_) => {
                return Err(MeshError::new(
                    place,
                    format!("{what} has a number that is not finite: `{word}`"),
                ))
            }
            None => {
                return Err(MeshError::new(
                    place,
                    format!("{what} needs {count} numbers, and `{word}` is not one"),
                ))
            }
        }
    }
    if found < count {
        return Err(MeshError::new(
            Place::Bytes(whole.clone()),
            format!("{what} needs {count} numbers, and this line has {found}"),
        ));
    }
    Ok(values)
}

/// One index of a face corner (`slot` 0 for a vertex, 1 a texture coordinate, 2 a normal),
/// as an index from 0: 1 to `defined` count from the start, -1 to -`defined` back from the
/// latest (OBJ's relative indices); 0 and anything else name nothing.
fn resolve(i: i64, defined: usize, slot: usize, place: &Range<usize>) -> Result<u32, MeshError> {
    let (what, plural) = [
        ("vertex", "vertices"),
        ("texture coordinate", "texture coordinates"),
        ("normal", "normals"),
    ][slot];
    let defined_i = defined as i64;
    let index = if (1..=defined_i).contains(&i) {
        Some(i - 1)
    } else if (-defined_i..=-1).contains(&i) {
        Some(defined_i + i)
    } else {
        None
    };
    match index.and_then(|index| u32::try_from(index).ok()) {
        Some(index) => Ok(index),
        None => Err(MeshError::new(
            Place::Bytes(place.clone()),
            match defined {
                1 => format!("{what} index {i} is out of range: 1 {what} is defined before this line"),
                _ => format!("{what} index {i} is out of range: {defined} {plural} are defined before this line"),
            },
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE_CORNERS: &str =
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n";

    /// The line (1-based) a place is on.
    fn line_of(bytes: &[u8], place: &Place) -> usize {
        match place {
            Place::Bytes(range) => 1 + bytes[..range.start].iter().filter(|&&b| b == b'\n').count(),
            Place::Line(line) => *line,
            Place::Whole => 0,
        }
    }

    #[test]
    fn quads_become_two_triangles_each_and_negative_indices_count_back() {
        let text = format!("{CUBE_CORNERS}f 1 2 3 4\nf -4 -3 -2 -1\n");
        let data = parse(text.as_bytes(), 100).unwrap();
        assert_eq!(data.positions.len(), 8);
        // Fans from the first corner, as tobj split them.
        assert_eq!(
            data.triangles,
            vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]]
        );
        assert!(data.normals.is_empty());
    }

    #[test]
    fn vertex_normals_come_one_per_vertex() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 0.6 0.8\nf 1//1 2//1 3//2\n";
        let data = parse(text.as_bytes(), 100).unwrap();
        assert_eq!(data.triangles.len(), 1);
        assert_eq!(data.normals.len(), data.positions.len());
        let t = data.triangles[0];
        assert_eq!(data.normals[t[2] as usize], [0.0, 0.6, 0.8]);
    }

    /// Vertices are those the faces use; their file numbers are kept for messages.
    #[test]
    fn unused_vertices_are_left_out_and_numbers_kept() {
        let text = "v 9 9 9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 2 3 4\n";
        let data = parse(text.as_bytes(), 100).unwrap();
        assert_eq!(
            data.positions,
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        );
        assert_eq!(data.vertex_numbers, VertexNumbers::Table(vec![2, 3, 4]));
        assert_eq!(data.face_starts, vec![32]);
    }

    #[test]
    fn a_weight_divides_the_coordinates() {
        let data = parse(b"v 2 4 6 2\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 100).unwrap();
        assert_eq!(data.positions[0], [1.0, 2.0, 3.0]);
        let error = parse(b"v 2 4 6 0\n", 100).unwrap_err();
        assert!(error.message.contains("weight"), "{error:?}");
    }

    #[test]
    fn errors_name_the_line() {
        let cases = [
            ("v 0 0 0\nv 1 0\n", 2, "needs 3 numbers"),
            ("v 0 0 0\nv 1 0 nan\n", 2, "not finite"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n",
                5,
                "vertex index 4 is out of range",
            ),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "vertex index 0"),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n",
                4,
                "vertex index -4",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n",
                4,
                "normal index 1",
            ),
            (
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 two 3\n",
                4,
                "`two` is not a face corner",
            ),
            (
                // The corner at fault is on the continued line.
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n 99\n",
                5,
                "vertex index 99",
            ),
            ("v 0 0 0\n\u{ff}\n", 2, "not UTF-8"),
        ];
        for (text, line, words) in cases {
            let bytes: Vec<u8> = if text.contains('\u{ff}') {
                text.replace('\u{ff}', "")
                    .bytes()
                    .take(8)
                    .chain([0xff, b'\n'])
                    .collect()
            } else {
                text.as_bytes().to_vec()
            };
            let error = parse(&bytes, 100).unwrap_err();
            assert_eq!(line_of(&bytes, &error.place), line, "{text:?}: {error:?}");
            assert!(error.message.contains(words), "{text:?}: {error:?}");
        }
    }

    /// Index arithmetic cannot overflow: an index past `i64` is malformed, and one past the
    /// vertices is out of range, whatever its size.
    #[test]
    fn huge_indices_are_errors_not_overflows() {
        for corner in [
            "9223372036854775807",
            "-9223372036854775808",
            "99999999999999999999",
        ] {
            let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 {corner}\n");
            let error = parse(text.as_bytes(), 100).unwrap_err();
            assert!(
                error.message.contains("out of range")
                    || error.message.contains("not a face corner"),
                "{corner}: {error:?}"
            );
        }
    }

    #[test]
    fn the_triangle_budget_is_checked_before_building() {
        let text = format!("{CUBE_CORNERS}f 1 2 3 4\nf 5 6 7 8\n");
        assert!(parse(text.as_bytes(), 4).is_ok());
        let error = parse(text.as_bytes(), 3).unwrap_err();
        assert_eq!(error.too_many, Some(4));
    }

    /// Every prefix of a file that uses every statement, and thousands of single-byte
    /// changes to it, end in a mesh or in an error; never a panic, and every place a
    /// message points at lies inside the file.
    #[test]
    fn prefixes_and_mutations_end_in_a_mesh_or_an_error_inside_the_file() {
        let text = "# made by hand\r\nmtllib a.mtl\r\no x\r\nv 0 0 0 # c\r\nv 1 0 0 1\r\nv 0 1 0\r\nv 0 0 \\\r\n 1\r\nvt 0 0\r\nvn 0 0 1\r\ns off\r\nusemtl m\r\nf 1/1/1 3/1/1 2/1/1\r\nf -4//1 -3//1 -1//1\r\nf 1 4 3 # side\r\nf 2 3 4\r\nl 1 2\r\nvx 1\r\ncurv 0 1 2\r\n";
        let bytes = text.as_bytes();
        let inside = |input: &[u8], place: &Range<usize>| {
            place.start <= place.end && place.end <= input.len()
        };
        let check = |input: &[u8]| match parse(input, 100) {
            Ok(data) => {
                for remark in &data.remarks {
                    assert!(inside(input, &remark.place), "{input:?}: {remark:?}");
                }
                for t in &data.triangles {
                    assert!(t.iter().all(|&i| (i as usize) < data.positions.len()));
                }
                assert_eq!(data.face_starts.len(), data.triangles.len());
            }
            Err(error) => {
                if let Place::Bytes(place) = &error.place {
                    assert!(inside(input, place), "{input:?}: {error:?}");
                }
            }
        };
        let whole = parse(bytes, 100).expect("the whole file reads");
        assert_eq!(whole.triangles.len(), 4);
        for end in 0..=bytes.len() {
            check(&bytes[..end]);
        }
        let replacements = [
            b' ', b'\n', b'\r', b'\\', b'#', b'/', b'-', b'0', b'9', b'f', b'v', 0xff,
        ];
        for at in 0..bytes.len() {
            for &byte in &replacements {
                let mut input = bytes.to_vec();
                input[at] = byte;
                check(&input);
            }
        }
    }

    #[test]
    fn ignored_statements_are_counted_per_keyword_and_capped() {
        let mut text = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        for k in 0..30 {
            text.push_str(&format!("junk{k} 1\njunk{k} 2\n"));
        }
        text.push_str("curv 0 1 1 2\n");
        let data = parse(text.as_bytes(), 100).unwrap();
        let messages: Vec<&str> = data.remarks.iter().map(|r| r.message.as_str()).collect();
        assert_eq!(messages.len(), MAX_KEYWORD_WARNINGS + 1, "{messages:#?}");
        assert_eq!(
            messages[0],
            "`junk0` is not an OBJ statement whitted knows; 2 lines use it (the first here), and they are ignored"
        );
        assert_eq!(
            messages[MAX_KEYWORD_WARNINGS],
            "more keywords whitted does not know; 41 lines have them (the first here), and they are ignored"
        );
        let data = parse(b"curv 0 1 1 2\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 100).unwrap();
        assert_eq!(
            data.remarks[0].message,
            "`curv` is an OBJ statement whitted does not read; this line is ignored"
        );
    }
}
