//! PLY (ASCII, binary little- and big-endian) through `ply-rs-bw`, the maintained ply-rs
//! fork (fuzzed, no unsafe, preallocation capped).
//!
//! Read: the `vertex` element (`x y z` of any scalar type, rounded to f32; `nx ny nz`;
//! `u v`, `s t` or `texture_u texture_v`; `red green blue [alpha]` or `diffuse_red ...`) and
//! the `face` element (`vertex_indices` or `vertex_index`, a list of any integer type),
//! polygons fanned, and the `tristrips` element of older scan archives (`vertex_indices`
//! lists of triangle strips separated by `-1`, winding alternating along a strip as in the
//! Stanford and VRIP tools; degenerate joining triangles dropped). Other elements (edges,
//! materials, ...) are read past and named in a warning.
//!
//! Before the payload is read, the element counts of the header are checked against the
//! bytes that follow it (each element needs at least its fixed binary size, or two bytes
//! per property in ASCII), so a 1 kB file that declares 10^10 faces is refused at once.

use std::io::Cursor;

use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, Property, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use super::{ReadMesh, count_of, push_fan, srgb_to_linear};

pub(super) fn read(bytes: &[u8]) -> Result<ReadMesh, String> {
    let mut reader = Reader::new(Cursor::new(bytes));
    let header =
        Parser::<Skip>::new().read_header(&mut reader).map_err(|err| format!("header: {}", first_lines(&err)))?;
    let payload_bytes = bytes.len() as u64 - reader.get_ref().position().min(bytes.len() as u64);
    check_counts(&header, payload_bytes)?;

    let mut mesh = ReadMesh::default();
    let mut vertex_attributes = None;
    let mut skipped = Vec::new();
    let mut short_faces = 0usize;
    for element in header.elements.values() {
        let read_error =
            |err: ply_rs_bw::parser::ParseError| format!("{} element: {}", element.name, first_lines(&err));
        match element.name.as_str() {
            "vertex" if vertex_attributes.is_none() => {
                let attributes = VertexAttributes::of(element)?;
                let vertices = Parser::<PlyVertex>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(read_error)?;
                attributes.store(&vertices, &mut mesh)?;
                vertex_attributes = Some(attributes);
            }
            "face" => {
                if element.count > 0 && !element.properties.keys().any(|k| is_index_list(k)) {
                    return Err("the face element has no 'vertex_indices' list".to_owned());
                }
                let faces = Parser::<PlyFace>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(read_error)?;
                let vertex_count = mesh.positions.len();
                mesh.triangles.reserve(faces.len());
                for (face, PlyFace { corners, negative }) in faces.iter().enumerate() {
                    if let Some(&bad) = corners.iter().find(|&&c| c as usize >= vertex_count) {
                        return Err(format!("face {face} uses vertex {bad}, but there are {vertex_count} vertices"));
                    }
                    if *negative {
                        return Err(format!("face {face} has a negative vertex index"));
                    }
                    if !push_fan(corners, &mut mesh.triangles) {
                        short_faces += 1;
                    }
                }
            }
            "tristrips" => {
                if element.count > 0 && !element.properties.keys().any(|k| is_index_list(k)) {
                    return Err("the tristrips element has no 'vertex_indices' list".to_owned());
                }
                let strips = Parser::<PlyStrip>::new()
                    .read_payload_for_element(&mut reader, element, &header)
                    .map_err(read_error)?;
                let vertex_count = mesh.positions.len();
                for (strip, PlyStrip { indices }) in strips.iter().enumerate() {
                    push_strips(indices, vertex_count, &mut mesh.triangles)
                        .map_err(|problem| format!("tristrips {strip}: {problem}"))?;
                }
            }
            _ => {
                Parser::<Skip>::new().read_payload_for_element(&mut reader, element, &header).map_err(read_error)?;
                skipped.push(count_of(
                    element.count,
                    &format!("{} element", element.name),
                    &format!("{} elements", element.name),
                ));
            }
        }
    }
    if vertex_attributes.is_none() {
        return Err("no vertex element".to_owned());
    }
    if short_faces > 0 {
        mesh.warnings.push(format!("skipped {} with fewer than 3 corners", count_of(short_faces, "face", "faces")));
    }
    if !skipped.is_empty() {
        mesh.warnings.push(format!("ignored: {}", skipped.join(", ")));
    }
    Ok(mesh)
}

/// The reader's message without the parser-internal detail (its `Error: ParseError {..}` line).
fn first_lines(err: &ply_rs_bw::parser::ParseError) -> String {
    let text = err.to_string();
    let kept: Vec<&str> = text.lines().filter(|line| !line.trim_start().starts_with("Error: ParseError")).collect();
    kept.iter().map(|line| line.trim()).collect::<Vec<_>>().join(" ")
}

fn is_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

fn scalar_bytes(scalar: &ScalarType) -> u64 {
    match scalar {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Refuses a header whose elements cannot fit in the `payload_bytes` after it.
fn check_counts(header: &Header, payload_bytes: u64) -> Result<(), String> {
    let mut needed: u128 = 0;
    for element in header.elements.values() {
        let per_element: u64 = element
            .properties
            .values()
            .map(|property| match (&header.encoding, &property.data_type) {
                (Encoding::Ascii, _) => 2,
                (_, PropertyType::Scalar(scalar)) => scalar_bytes(scalar),
                (_, PropertyType::List(count, _)) => scalar_bytes(count),
            })
            .sum();
        needed += element.count as u128 * per_element.max(1) as u128;
        if needed > payload_bytes as u128 {
            return Err(format!(
                "the header declares {} '{}' elements, which need at least {needed} bytes, but only {payload_bytes} \
                 bytes follow the header",
                element.count, element.name
            ));
        }
    }
    Ok(())
}

/// Which vertex properties the header declares.
struct VertexAttributes {
    normals: bool,
    uvs: bool,
    colors: bool,
}

impl VertexAttributes {
    fn of(element: &ElementDef) -> Result<Self, String> {
        let has = |name: &str| element.properties.contains_key(name);
        if !(has("x") && has("y") && has("z")) {
            return Err("the vertex element lacks x, y or z".to_owned());
        }
        Ok(VertexAttributes {
            normals: has("nx") && has("ny") && has("nz"),
            uvs: (has("u") && has("v")) || (has("s") && has("t")) || (has("texture_u") && has("texture_v")),
            colors: (has("red") && has("green") && has("blue"))
                || (has("diffuse_red") && has("diffuse_green") && has("diffuse_blue")),
        })
    }

    fn store(&self, vertices: &[PlyVertex], mesh: &mut ReadMesh) -> Result<(), String> {
        mesh.positions.reserve(vertices.len());
        for (index, vertex) in vertices.iter().enumerate() {
            let position = vertex.position.map(|x| x as f32);
            if !position.iter().all(|x| x.is_finite()) {
                return Err(format!("vertex {index} has a non-finite coordinate {:?}", vertex.position));
            }
            mesh.positions.push(position);
        }
        if self.normals {
            mesh.normals = vertices.iter().map(|v| v.normal).collect();
        }
        if self.uvs {
            mesh.uvs = vertices.iter().map(|v| v.uv).collect();
        }
        if self.colors {
            mesh.colors = vertices
                .iter()
                .map(|v| {
                    let [r, g, b, a] = v.color;
                    [srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(b), a.clamp(0.0, 1.0)]
                })
                .collect();
        }
        Ok(())
    }
}

/// A scalar property as f64 (lists: `None`).
fn scalar(property: &Property) -> Option<f64> {
    Some(match *property {
        Property::Char(v) => v.into(),
        Property::UChar(v) => v.into(),
        Property::Short(v) => v.into(),
        Property::UShort(v) => v.into(),
        Property::Int(v) => v.into(),
        Property::UInt(v) => v.into(),
        Property::Float(v) => v.into(),
        Property::Double(v) => v,
        _ => return None,
    })
}

/// A colour channel in `[0, 1]`: integers over their type's maximum, floats as they are.
fn channel(property: &Property) -> Option<f32> {
    let max = match property {
        Property::UChar(_) => 255.0,
        Property::UShort(_) => 65535.0,
        Property::UInt(_) => u32::MAX as f64,
        Property::Char(_) => 127.0,
        Property::Short(_) => 32767.0,
        Property::Int(_) => i32::MAX as f64,
        _ => 1.0,
    };
    scalar(property).map(|v| (v / max) as f32)
}

#[derive(Debug)]
struct PlyVertex {
    position: [f64; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    color: [f32; 4],
}

impl PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex { position: [0.0; 3], normal: [0.0, 0.0, 1.0], uv: [0.0; 2], color: [1.0; 4] }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        let value = || scalar(&property);
        let slot: Option<(&mut f32, f32)> = match name {
            "x" | "y" | "z" => {
                let axis = usize::from(name.as_bytes()[0] - b'x');
                return match value() {
                    Some(v) => {
                        self.position[axis] = v;
                        PropertyAccessResult::Set
                    }
                    None => PropertyAccessResult::UnsupportedType,
                };
            }
            "nx" => value().map(|v| (&mut self.normal[0], v as f32)),
            "ny" => value().map(|v| (&mut self.normal[1], v as f32)),
            "nz" => value().map(|v| (&mut self.normal[2], v as f32)),
            "u" | "s" | "texture_u" => value().map(|v| (&mut self.uv[0], v as f32)),
            // PLY texture coordinates have a bottom-left origin; glTF's is top-left.
            "v" | "t" | "texture_v" => value().map(|v| (&mut self.uv[1], 1.0 - v as f32)),
            "red" | "diffuse_red" => channel(&property).map(|v| (&mut self.color[0], v)),
            "green" | "diffuse_green" => channel(&property).map(|v| (&mut self.color[1], v)),
            "blue" | "diffuse_blue" => channel(&property).map(|v| (&mut self.color[2], v)),
            "alpha" => channel(&property).map(|v| (&mut self.color[3], v)),
            _ => return PropertyAccessResult::Ignored,
        };
        match slot {
            Some((slot, v)) => {
                *slot = v;
                PropertyAccessResult::Set
            }
            None => PropertyAccessResult::Ignored,
        }
    }
}

#[derive(Debug)]
struct PlyFace {
    corners: Vec<u32>,
    negative: bool,
}

impl PropertyAccess for PlyFace {
    fn new() -> Self {
        PlyFace { corners: Vec::new(), negative: false }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        fn convert<T: Copy + TryInto<u32>>(values: &[T], negative: &mut bool) -> Vec<u32> {
            values
                .iter()
                .map(|&v| {
                    v.try_into().unwrap_or_else(|_| {
                        *negative = true;
                        0
                    })
                })
                .collect()
        }
        let negative = &mut self.negative;
        self.corners = match &property {
            Property::ListChar(v) => convert(v, negative),
            Property::ListUChar(v) => convert(v, negative),
            Property::ListShort(v) => convert(v, negative),
            Property::ListUShort(v) => convert(v, negative),
            Property::ListInt(v) => convert(v, negative),
            Property::ListUInt(v) => v.clone(),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// One entry of a `tristrips` element: vertex ids, `-1` between strips.
#[derive(Debug)]
struct PlyStrip {
    indices: Vec<i64>,
}

impl PropertyAccess for PlyStrip {
    fn new() -> Self {
        PlyStrip { indices: Vec::new() }
    }

    fn set_property(&mut self, name: &str, property: Property) -> PropertyAccessResult {
        if !is_index_list(name) {
            return PropertyAccessResult::Ignored;
        }
        fn widen<T: Copy + Into<i64>>(values: &[T]) -> Vec<i64> {
            values.iter().map(|&v| v.into()).collect()
        }
        self.indices = match &property {
            Property::ListChar(v) => widen(v),
            Property::ListUChar(v) => widen(v),
            Property::ListShort(v) => widen(v),
            Property::ListUShort(v) => widen(v),
            Property::ListInt(v) => widen(v),
            Property::ListUInt(v) => widen(v),
            _ => return PropertyAccessResult::UnsupportedType,
        };
        PropertyAccessResult::Set
    }
}

/// Appends the triangles of the strips in `indices` (separated by `-1`): triangle `k` of a
/// strip is `(s[k], s[k+1], s[k+2])` for even `k` and `(s[k+1], s[k], s[k+2])` for odd `k`, so
/// every triangle keeps the first one's winding; triangles with a repeated vertex (the
/// joins between strips) are dropped. Refuses an id outside `0..vertex_count` other than
/// the `-1` separator.
fn push_strips(indices: &[i64], vertex_count: usize, triangles: &mut Vec<[u32; 3]>) -> Result<(), String> {
    for strip in indices.split(|&v| v == -1) {
        let mut ids = Vec::with_capacity(strip.len());
        for &v in strip {
            match u32::try_from(v) {
                Ok(id) if (id as usize) < vertex_count => ids.push(id),
                _ => return Err(format!("vertex {v} outside 0..{vertex_count} (only -1 separates strips)")),
            }
        }
        for (k, w) in ids.windows(3).enumerate() {
            let triangle = if k % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] };
            if triangle[0] != triangle[1] && triangle[1] != triangle[2] && triangle[0] != triangle[2] {
                triangles.push(triangle);
            }
        }
    }
    Ok(())
}

/// Any other element: every property read past and dropped.
#[derive(Debug)]
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}
