//! Stanford `.ply` files, ASCII and binary (either byte order): the `vertex` element's `x`,
//! `y`, `z` (and `nx`, `ny`, `nz` when all three are there) and the `face` element's
//! `vertex_indices` (or `vertex_index`) lists; every other element and property is read past.
//!
//! A small reader of its own rather than ply-rs: that crate (0.1.3, last released in 2020)
//! builds a documentation tester (skeptic) as a build dependency, and panics are not ruled
//! out on bad input, where this reader's every problem is an error naming the line (ASCII)
//! or the byte (binary) at fault.

use super::{MeshData, MeshError, VertexNumbers};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Format {
    Ascii,
    Binary { big_endian: bool },
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(word: &str) -> Option<Scalar> {
        Some(match word {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list.
    list: Option<Scalar>,
    item: Scalar,
}

#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// Parses a PLY file of at most `budget` triangles.
pub(super) fn parse(bytes: &[u8], budget: usize) -> Result<MeshData, MeshError> {
    let Header {
        format,
        elements,
        body,
        lines: header_lines,
    } = header(bytes)?;
    let mut reader = match format {
        Format::Ascii => Reader::Ascii {
            text: body,
            at: 0,
            offset: bytes.len() - body.len(),
            line: header_lines,
            words_left: 0,
        },
        Format::Binary { big_endian } => Reader::Binary {
            bytes: body,
            at: 0,
            offset: bytes.len() - body.len(),
            big_endian,
        },
    };
    let mut data = MeshData {
        vertex_numbers: VertexNumbers::FromZero,
        ..MeshData::default()
    };
    let mut triangles = 0usize;
    for element in &elements {
        let is_vertex = element.name == "vertex";
        let is_face = element.name == "face";
        let find = |name: &str| element.properties.iter().position(|p| p.name == name);
        let xyz = [find("x"), find("y"), find("z")];
        let normal = [find("nx"), find("ny"), find("nz")];
        let has_normals = is_vertex && normal.iter().all(Option::is_some);
        let corners = find("vertex_indices").or_else(|| find("vertex_index"));
        if is_vertex && xyz.iter().any(Option::is_none) {
            return Err(MeshError::whole(
                "its `vertex` element lacks one of the properties `x`, `y`, `z`",
            ));
        }
        if is_face && corners.is_none_or(|i| element.properties[i].list.is_none()) {
            return Err(MeshError::whole(
                "its `face` element has no `vertex_indices` list",
            ));
        }
        for _ in 0..element.count {
            reader.start_record();
            let record_start = reader.record_start();
            let mut values = [0.0f64; 6];
            for (index, property) in element.properties.iter().enumerate() {
                match property.list {
                    None => {
                        let value = reader.scalar(property.item)?;
                        if is_vertex {
                            for (slot, wanted) in xyz.iter().chain(&normal).enumerate() {
                                if *wanted == Some(index) {
                                    values[slot] = value;
                                }
                            }
                        }
                    }
                    Some(count_type) => {
                        let count = reader.scalar(count_type)?;
                        if !(count >= 0.0 && count.fract() == 0.0 && count <= 1e6) {
                            return Err(reader.error(format!(
                                "a list of {count} items is not a list whitted reads"
                            )));
                        }
                        let count = count as usize;
                        let mut corner_ids = Vec::new();
                        for _ in 0..count {
                            let value = reader.scalar(property.item)?;
                            if is_face && Some(index) == corners {
                                corner_ids.push(value);
                            }
                        }
                        if is_face && Some(index) == corners {
                            if count < 3 {
                                return Err(reader.error(format!(
                                    "a face needs three vertices or more, and this one has {}",
                                    if count == 0 {
                                        "none".to_string()
                                    } else {
                                        count.to_string()
                                    }
                                )));
                            }
                            triangles = triangles.saturating_add(count - 2);
                            if triangles > budget {
                                return Err(MeshError::too_many(triangles));
                            }
                            let vertices = data.positions.len();
                            let mut ids = Vec::with_capacity(corner_ids.len());
                            for value in corner_ids {
                                if !(value >= 0.0
                                    && value.fract() == 0.0
                                    && value < vertices as f64)
                                {
                                    return Err(reader.error(format!(
                                        "vertex index {value} is out of range: there are {vertices} vertices"
                                    )));
                                }
                                ids.push(value as u32);
                            }
                            // A fan, as for OBJ polygons.
                            for k in 1..ids.len().saturating_sub(1) {
                                data.triangles.push([ids[0], ids[k], ids[k + 1]]);
                                data.face_starts.extend(record_start);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                let as_f32 = |slots: std::ops::Range<usize>| -> Option<[f32; 3]> {
                    let v = &values[slots];
                    let p = [v[0] as f32, v[1] as f32, v[2] as f32];
                    p.iter().all(|x| x.is_finite()).then_some(p)
                };
                let Some(position) = as_f32(0..3) else {
                    return Err(reader.error("a vertex has a coordinate that is not finite"));
                };
                data.positions.push(position);
                if has_normals {
                    let Some(n) = as_f32(3..6) else {
                        return Err(reader.error("a vertex normal is not finite"));
                    };
                    data.normals.push(n);
                }
            }
        }
    }
    Ok(data)
}

/// What the header says, and where the body starts.
struct Header<'a> {
    format: Format,
    elements: Vec<Element>,
    /// The bytes after `end_header`.
    body: &'a [u8],
    /// How many lines the header took.
    lines: usize,
}

/// Reads the header.
fn header(bytes: &[u8]) -> Result<Header<'_>, MeshError> {
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut at = 0usize;
    let mut line_number = 0usize;
    loop {
        let Some(length) = bytes[at..].iter().position(|&b| b == b'\n') else {
            return Err(MeshError::whole("its header has no `end_header` line"));
        };
        line_number += 1;
        let raw = &bytes[at..at + length];
        at += length + 1;
        let Ok(line) = std::str::from_utf8(raw) else {
            return Err(MeshError::at(line_number, "this header line is not text"));
        };
        let words: Vec<&str> = line.split_whitespace().collect();
        let bad = |message: &str| Err(MeshError::at(line_number, message));
        match words.as_slice() {
            ["ply"] if line_number == 1 => {}
            _ if line_number == 1 => return bad("a PLY file starts with the line `ply`"),
            ["format", kind, _version] => {
                format =
                    Some(match *kind {
                        "ascii" => Format::Ascii,
                        "binary_little_endian" => Format::Binary { big_endian: false },
                        "binary_big_endian" => Format::Binary { big_endian: true },
                        _ => return bad(
                            "the format is `ascii`, `binary_little_endian` or `binary_big_endian`",
                        ),
                    });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let Ok(count) = count.parse::<usize>() else {
                    return bad("an element's count must be a whole number");
                };
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count_type, item_type, name] => {
                let (Some(list), Some(item)) =
                    (Scalar::parse(count_type), Scalar::parse(item_type))
                else {
                    return bad("unknown property type");
                };
                let Some(element) = elements.last_mut() else {
                    return bad("a property before any element");
                };
                element.properties.push(Property {
                    name: name.to_string(),
                    list: Some(list),
                    item,
                });
            }
            ["property", item_type, name] => {
                let Some(item) = Scalar::parse(item_type) else {
                    return bad("unknown property type");
                };
                let Some(element) = elements.last_mut() else {
                    return bad("a property before any element");
                };
                element.properties.push(Property {
                    name: name.to_string(),
                    list: None,
                    item,
                });
            }
            ["end_header"] => break,
            _ => return bad("not a PLY header line"),
        }
    }
    let Some(format) = format else {
        return Err(MeshError::whole("its header has no `format` line"));
    };
    Ok(Header {
        format,
        elements,
        body: &bytes[at..],
        lines: line_number,
    })
}

/// Reads the numbers of the body, one at a time.
enum Reader<'a> {
    Ascii {
        text: &'a [u8],
        at: usize,
        /// Where the body starts in the file.
        offset: usize,
        /// The line the last record started on (1-based, counting the header).
        line: usize,
        /// Words still to read on the current line (records are one per line).
        words_left: usize,
    },
    Binary {
        bytes: &'a [u8],
        at: usize,
        /// Where the body starts in the file, for messages.
        offset: usize,
        big_endian: bool,
    },
}

impl Reader<'_> {
    /// An ASCII record is one line: move to the next.
    fn start_record(&mut self) {
        if let Reader::Ascii {
            text,
            at,
            line,
            words_left,
            ..
        } = self
        {
            // The rest of the previous record's line, if it had more words than properties.
            if *words_left > 0 {
                *at = text[*at..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(text.len(), |p| *at + p + 1);
            }
            // Skip blank lines.
            while *at < text.len() {
                let end = text[*at..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(text.len(), |p| *at + p);
                *line += 1;
                let blank = text[*at..end].iter().all(u8::is_ascii_whitespace);
                if !blank {
                    *words_left = text[*at..end]
                        .split(u8::is_ascii_whitespace)
                        .filter(|w| !w.is_empty())
                        .count();
                    return;
                }
                *at = (end + 1).min(text.len());
            }
            *words_left = 0;
        }
    }

    /// Where the current record starts in the file (ASCII files; a binary file has no
    /// line to show).
    fn record_start(&self) -> Option<usize> {
        match self {
            Reader::Ascii { at, offset, .. } => Some(offset + at),
            Reader::Binary { .. } => None,
        }
    }

    fn error(&self, message: impl Into<String>) -> MeshError {
        match self {
            Reader::Ascii { line, .. } => MeshError::at(*line, message),
            Reader::Binary { at, offset, .. } => {
                MeshError::whole(format!("{} (at byte {})", message.into(), offset + at))
            }
        }
    }

    fn scalar(&mut self, kind: Scalar) -> Result<f64, MeshError> {
        match self {
            Reader::Ascii {
                text,
                at,
                words_left,
                ..
            } => {
                if *words_left == 0 {
                    return Err(self.error("this line ends before its element does"));
                }
                while *at < text.len() && text[*at].is_ascii_whitespace() && text[*at] != b'\n' {
                    *at += 1;
                }
                let start = *at;
                while *at < text.len() && !text[*at].is_ascii_whitespace() {
                    *at += 1;
                }
                *words_left -= 1;
                let word = std::str::from_utf8(&text[start..*at]).unwrap_or("");
                if *words_left == 0 {
                    // The record's last word: step past its line's end.
                    while *at < text.len() && text[*at] != b'\n' {
                        *at += 1;
                    }
                    *at = (*at + 1).min(text.len());
                }
                let value = word.parse::<f64>();
                match (value, kind) {
                    (Ok(x), Scalar::F32 | Scalar::F64) => Ok(x),
                    (Ok(x), _) if x.fract() == 0.0 => Ok(x),
                    _ => Err(self.error(format!("`{word}` is not a {kind:?} number"))),
                }
            }
            Reader::Binary {
                bytes,
                at,
                big_endian,
                ..
            } => {
                let size = kind.size();
                let Some(raw) = bytes.get(*at..*at + size) else {
                    return Err(self.error("the file ends in the middle of its data"));
                };
                let mut buffer = [0u8; 8];
                buffer[..size].copy_from_slice(raw);
                if *big_endian {
                    buffer[..size].reverse();
                }
                *at += size;
                let b = buffer;
                Ok(match kind {
                    Scalar::I8 => f64::from(b[0] as i8),
                    Scalar::U8 => f64::from(b[0]),
                    Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
                    Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
                    Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
                    Scalar::F64 => f64::from_le_bytes(b),
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Place;

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment a square\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn an_ascii_square_is_two_triangles() {
        let data = parse(ASCII.as_bytes(), 10).unwrap();
        assert_eq!(data.positions.len(), 4);
        assert_eq!(data.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(data.normals.is_empty());
    }

    /// The same square in binary, both byte orders, with normals and an extra property.
    #[test]
    fn binary_files_of_either_byte_order_read_alike() {
        for big_endian in [false, true] {
            let order = if big_endian { "big" } else { "little" };
            let mut bytes = format!(
                "ply\nformat binary_{order}_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n"
            )
            .into_bytes();
            let f = |x: f32| {
                if big_endian {
                    x.to_be_bytes()
                } else {
                    x.to_le_bytes()
                }
            };
            for p in [
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ] {
                for x in p {
                    bytes.extend(f(x));
                }
                bytes.push(200);
                for x in [0.0, 0.0, 1.0] {
                    bytes.extend(f(x));
                }
            }
            bytes.push(4);
            for i in [0u32, 1, 2, 3] {
                bytes.extend(if big_endian {
                    i.to_be_bytes()
                } else {
                    i.to_le_bytes()
                });
            }
            let data = parse(&bytes, 10).unwrap();
            assert_eq!(data.positions[2], [1.0, 1.0, 0.0], "{order}");
            assert_eq!(data.normals.len(), 4, "{order}");
            assert_eq!(data.triangles, vec![[0, 1, 2], [0, 2, 3]], "{order}");
        }
    }

    #[test]
    fn errors_name_the_line_or_the_byte() {
        let bad_index = ASCII.replace("4 0 1 2 3", "4 0 1 2 9");
        let error = parse(bad_index.as_bytes(), 10).unwrap_err();
        assert_eq!(error.place, Place::Line(15), "{error:?}");
        assert!(error.message.contains("vertex index 9"), "{error:?}");
        let short_vertex = ASCII.replace("1 1 0\n", "1 1\n");
        let error = parse(short_vertex.as_bytes(), 10).unwrap_err();
        assert_eq!(error.place, Place::Line(13), "{error:?}");
        let bad_header = ASCII.replace("property float y", "property floaty y");
        let error = parse(bad_header.as_bytes(), 10).unwrap_err();
        assert_eq!(error.place, Place::Line(6), "{error:?}");
        let truncated = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n\0\0";
        let error = parse(truncated.as_bytes(), 10).unwrap_err();
        assert!(error.message.contains("at byte"), "{error:?}");
        assert!(parse(ASCII.as_bytes(), 1).unwrap_err().too_many.is_some());
        let short_face = ASCII.replace("4 0 1 2 3", "2 0 1");
        let error = parse(short_face.as_bytes(), 10).unwrap_err();
        assert_eq!(error.place, Place::Line(15), "{error:?}");
        assert!(error.message.contains("this one has 2"), "{error:?}");
    }

    /// Each triangle knows its face's line, for the messages of a mesh that is not a
    /// solid; a binary file's triangles have none.
    #[test]
    fn ascii_triangles_know_where_their_face_is() {
        let data = parse(ASCII.as_bytes(), 10).unwrap();
        let start = ASCII.find("4 0 1 2 3").unwrap();
        assert_eq!(data.face_starts, vec![start, start]);
    }
}
