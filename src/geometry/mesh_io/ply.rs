//! PLY (ASCII, binary little- or big-endian) through `ply-rs-bw`.
//!
//! The parser trusts the counts a file declares: it reserves memory for `count` elements, and
//! for `n` list items, before reading them. A corrupt count (a flipped bit in `element face`, a
//! garbage list length) would then ask for gigabytes and abort the process. So before handing
//! the payload to the parser, [`check_counts`] walks its layout — sizes and list lengths only,
//! no values — and refuses any count that the remaining bytes (binary) or tokens (ASCII) could
//! not hold. The parser's allocations are then bounded by the file's size.

use super::MeshLoadError;
use crate::geometry::TriMesh;
use glam::Vec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, Property, PropertyAccess, PropertyType, ScalarType,
};
use std::io::Cursor;

const FORMAT: &str = "PLY";

fn parse_error(message: impl Into<String>) -> MeshLoadError {
    MeshLoadError::Parse {
        format: FORMAT,
        message: message.into(),
    }
}

fn unsupported(message: impl Into<String>) -> MeshLoadError {
    MeshLoadError::Unsupported {
        format: FORMAT,
        message: message.into(),
    }
}

/// Reads a PLY file's `vertex` element (`x`, `y`, `z`, any numeric type) and `face` element
/// (a `vertex_indices` or `vertex_index` list of any integer type; polygons split into fans
/// around their first corner; faces of fewer than 3 corners skipped). Other elements and
/// properties are read past and ignored.
pub fn read_ply(bytes: &[u8]) -> Result<TriMesh, MeshLoadError> {
    let mut cursor = Cursor::new(bytes);
    let header = Parser::<Ignored>::new()
        .read_header(&mut cursor)
        .map_err(|e| parse_error(e.to_string()))?;
    let payload = bytes.get(cursor.position() as usize..).unwrap_or_default();
    check_layout(&header)?;
    check_counts(&header, payload)?;
    let (mut vertices, mut faces) = (Vec::new(), Vec::new());
    for (name, element) in &header.elements {
        let read = |e| parse_error(format!("element '{name}': {e}"));
        match name.as_str() {
            "vertex" => {
                vertices = read_element::<PlyVertex>(&mut cursor, element, &header).map_err(read)?
            }
            "face" => {
                faces = read_element::<PlyFace>(&mut cursor, element, &header).map_err(read)?
            }
            _ => {
                read_element::<Ignored>(&mut cursor, element, &header).map_err(read)?;
            }
        }
    }
    let vertices = vertices
        .iter()
        .map(|v| {
            Vec3::new(
                v.position[0] as f32,
                v.position[1] as f32,
                v.position[2] as f32,
            )
        })
        .collect();
    let mut triangles = Vec::new();
    for (i, face) in faces.iter().enumerate() {
        if face.negative_index {
            return Err(parse_error(format!("face {i} has a negative vertex index")));
        }
        let corners = &face.indices;
        for k in 1..corners.len().saturating_sub(1) {
            triangles.push([corners[0], corners[k], corners[k + 1]]);
        }
    }
    if triangles.is_empty() {
        return Err(unsupported("no face with 3 or more corners"));
    }
    Ok(TriMesh::new(vertices, triangles)?)
}

fn read_element<E: PropertyAccess>(
    cursor: &mut Cursor<&[u8]>,
    element: &ElementDef,
    header: &Header,
) -> std::io::Result<Vec<E>> {
    Parser::<E>::new().read_payload_for_element(cursor, element, header)
}

/// The file has what a mesh needs: vertices with numeric `x`, `y`, `z`, and faces with an
/// integer index list.
fn check_layout(header: &Header) -> Result<(), MeshLoadError> {
    let vertex = header
        .elements
        .get("vertex")
        .ok_or_else(|| unsupported("no 'vertex' element"))?;
    for axis in ["x", "y", "z"] {
        match vertex.properties.get(axis).map(|p| &p.data_type) {
            Some(PropertyType::Scalar(_)) => {}
            _ => return Err(unsupported(format!("vertices have no scalar '{axis}'"))),
        }
    }
    let face = header
        .elements
        .get("face")
        .ok_or_else(|| unsupported("no 'face' element (a point cloud?)"))?;
    match face_list(face).map(|p| &p.data_type) {
        Some(PropertyType::List(_, item)) if is_integer(item) => Ok(()),
        Some(_) => Err(unsupported("face indices are not an integer list")),
        None => Err(unsupported("faces have no 'vertex_indices' list")),
    }
}

fn face_list(face: &ElementDef) -> Option<&ply_rs_bw::ply::PropertyDef> {
    FACE_LIST_NAMES
        .iter()
        .find_map(|name| face.properties.get(*name))
}

const FACE_LIST_NAMES: [&str; 2] = ["vertex_indices", "vertex_index"];

fn is_integer(t: &ScalarType) -> bool {
    !matches!(t, ScalarType::Float | ScalarType::Double)
}

fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Refuses declared counts that the payload cannot hold (see the module notes).
fn check_counts(header: &Header, payload: &[u8]) -> Result<(), MeshLoadError> {
    match header.encoding {
        Encoding::Ascii => check_ascii_counts(header, payload),
        Encoding::BinaryLittleEndian => check_binary_counts(header, payload, false),
        Encoding::BinaryBigEndian => check_binary_counts(header, payload, true),
    }
}

fn check_binary_counts(
    header: &Header,
    payload: &[u8],
    big_endian: bool,
) -> Result<(), MeshLoadError> {
    let mut at = 0usize;
    for (name, element) in &header.elements {
        let remaining = payload.len() - at;
        if element.count > remaining {
            return Err(parse_error(format!(
                "element '{name}' declares {} entries but only {remaining} bytes follow",
                element.count
            )));
        }
        for _ in 0..element.count {
            for (property, def) in &element.properties {
                at = skip_binary_property(payload, at, &def.data_type, big_endian).ok_or_else(
                    || parse_error(format!("truncated or corrupt '{name}.{property}'")),
                )?;
            }
        }
    }
    Ok(())
}

/// The offset after one binary property at `at`, or `None` past the end of the payload or for
/// a list whose length is negative or not an integer.
fn skip_binary_property(
    payload: &[u8],
    at: usize,
    t: &PropertyType,
    big_endian: bool,
) -> Option<usize> {
    let end = match t {
        PropertyType::Scalar(s) => at.checked_add(scalar_size(s))?,
        PropertyType::List(count_type, item) => {
            let size = scalar_size(count_type);
            let raw = payload.get(at..at.checked_add(size)?)?;
            let count = list_length(raw, count_type, big_endian)?;
            at.checked_add(size)?
                .checked_add(count.checked_mul(scalar_size(item))?)?
        }
    };
    (end <= payload.len()).then_some(end)
}

fn list_length(raw: &[u8], t: &ScalarType, big_endian: bool) -> Option<usize> {
    let mut bytes = [0u8; 8];
    let n = raw.len();
    if big_endian {
        bytes[8 - n..].copy_from_slice(raw);
        bytes.reverse();
    } else {
        bytes[..n].copy_from_slice(raw);
    }
    let unsigned = u64::from_le_bytes(bytes);
    let negative = match t {
        ScalarType::Char => unsigned >= 1 << 7,
        ScalarType::Short => unsigned >= 1 << 15,
        ScalarType::Int => unsigned >= 1 << 31,
        ScalarType::Float | ScalarType::Double => return None,
        _ => false,
    };
    if negative {
        None
    } else {
        usize::try_from(unsigned).ok()
    }
}

fn check_ascii_counts(header: &Header, payload: &[u8]) -> Result<(), MeshLoadError> {
    let text = std::str::from_utf8(payload)
        .map_err(|e| parse_error(format!("ASCII payload is not UTF-8: {e}")))?;
    let mut lines = text.split('\n');
    for (name, element) in &header.elements {
        for i in 0..element.count {
            let line = lines.next().ok_or_else(|| {
                parse_error(format!(
                    "element '{name}' declares {} entries but ends at {i}",
                    element.count
                ))
            })?;
            let mut tokens = line.split_ascii_whitespace();
            for (property, def) in &element.properties {
                let fits = match &def.data_type {
                    PropertyType::Scalar(_) => tokens.next().is_some(),
                    PropertyType::List(..) => {
                        let count = tokens.next().and_then(|c| c.parse::<usize>().ok());
                        count.is_some_and(|n| tokens.by_ref().take(n).count() == n)
                    }
                };
                if !fits {
                    return Err(parse_error(format!(
                        "'{name}' {i}: '{property}' is missing or too short"
                    )));
                }
            }
        }
    }
    Ok(())
}

/// Elements the mesh does not need: every property is dropped as it is read.
struct Ignored;

impl PropertyAccess for Ignored {
    fn new() -> Self {
        Ignored
    }
}

/// A vertex: the three coordinates, whatever their stored type.
#[derive(Default)]
struct PlyVertex {
    position: [f64; 3],
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) {
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return,
        };
        // `check_layout` made x, y, z scalars, so every variant here is numeric.
        self.position[axis] = match property {
            Property::Char(v) => v.into(),
            Property::UChar(v) => v.into(),
            Property::Short(v) => v.into(),
            Property::UShort(v) => v.into(),
            Property::Int(v) => v.into(),
            Property::UInt(v) => v.into(),
            Property::Float(v) => v.into(),
            Property::Double(v) => v,
            _ => f64::NAN,
        };
    }
}

/// A face: its corner indices, and whether one was negative.
#[derive(Default)]
struct PlyFace {
    indices: Vec<u32>,
    negative_index: bool,
}

impl PlyFace {
    fn set_signed(&mut self, values: impl Iterator<Item = i64>) {
        for v in values {
            match u32::try_from(v) {
                Ok(i) => self.indices.push(i),
                Err(_) => self.negative_index = true,
            }
        }
    }
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        Self::default()
    }

    fn set_property(&mut self, name: &str, property: Property) {
        if !FACE_LIST_NAMES.contains(&name) {
            return;
        }
        match property {
            Property::ListChar(v) => self.set_signed(v.into_iter().map(i64::from)),
            Property::ListUChar(v) => self.indices = v.into_iter().map(u32::from).collect(),
            Property::ListShort(v) => self.set_signed(v.into_iter().map(i64::from)),
            Property::ListUShort(v) => self.indices = v.into_iter().map(u32::from).collect(),
            Property::ListInt(v) => self.set_signed(v.into_iter().map(i64::from)),
            Property::ListUInt(v) => self.indices = v,
            // `check_layout` refused float index lists.
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n\
        property float y\nproperty double z\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";

    #[test]
    fn ascii_quad_becomes_a_fan() {
        let m = read_ply(SQUARE.as_bytes()).unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.vertices()[2], Vec3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn corrupt_counts_are_refused_before_parsing() {
        let huge_element = SQUARE.replace("element face 1", "element face 99999999999");
        assert!(matches!(
            read_ply(huge_element.as_bytes()),
            Err(MeshLoadError::Parse { .. })
        ));
        let huge_list = SQUARE.replace("4 0 1 2 3", "4000000000 0 1 2 3");
        assert!(matches!(
            read_ply(huge_list.as_bytes()),
            Err(MeshLoadError::Parse { .. })
        ));
        let short_line = SQUARE.replace("1 1 0\n", "1 1\n");
        assert!(matches!(
            read_ply(short_line.as_bytes()),
            Err(MeshLoadError::Parse { .. })
        ));
    }

    #[test]
    fn binary_list_lengths_are_bounded_by_the_bytes() {
        let mut file = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\n\
            property float x\nproperty float y\nproperty float z\nelement face 1\n\
            property list uint int vertex_indices\nend_header\n"
            .to_vec();
        for v in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            v.iter().for_each(|c| file.extend(c.to_le_bytes()));
        }
        let mut good = file.clone();
        good.extend(3u32.to_le_bytes());
        [0i32, 1, 2]
            .iter()
            .for_each(|i| good.extend(i.to_le_bytes()));
        assert_eq!(read_ply(&good).unwrap().triangle_count(), 1);
        let mut corrupt = file.clone();
        corrupt.extend(u32::MAX.to_le_bytes());
        [0i32, 1, 2]
            .iter()
            .for_each(|i| corrupt.extend(i.to_le_bytes()));
        assert!(matches!(
            read_ply(&corrupt),
            Err(MeshLoadError::Parse { .. })
        ));
        let mut negative = file;
        negative.extend(3u32.to_le_bytes());
        [0i32, -1, 2]
            .iter()
            .for_each(|i| negative.extend(i.to_le_bytes()));
        assert!(matches!(
            read_ply(&negative),
            Err(MeshLoadError::Parse { .. })
        ));
    }

    #[test]
    fn missing_elements_are_unsupported() {
        let cloud = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n\
            property float y\nproperty float z\nend_header\n0 0 0\n";
        assert!(matches!(
            read_ply(cloud.as_bytes()),
            Err(MeshLoadError::Unsupported { .. })
        ));
        let float_indices = SQUARE.replace("list uchar int", "list uchar float");
        assert!(matches!(
            read_ply(float_indices.as_bytes()),
            Err(MeshLoadError::Unsupported { .. })
        ));
    }
}
