//! Accessors: element formats, the memory budget, buffer views and the bounds-checked,
//! budgeted reading of accessor elements (dense, strided or zero, then sparse).

use gltf::json;
use gltf::json::accessor::{ComponentType, Type};
use gltf::json::validation::Checked;

use super::container::load_buffer;
use super::{BUDGET_PER_INPUT_BYTE, Fail, Importer, invalid};

/// The element decoder an accessor is read with.
pub(super) type Decode<T> = fn(&[u8], ElementFormat) -> Option<T>;

/// Float components only.
pub(super) const FLOAT: &[(ComponentType, bool)] = &[(ComponentType::F32, false)];
/// Float, normalized unsigned byte or normalized unsigned short components.
pub(super) const FLOAT_OR_UNORM: &[(ComponentType, bool)] =
    &[(ComponentType::F32, false), (ComponentType::U8, true), (ComponentType::U16, true)];
/// Unsigned integer components (indices).
pub(super) const UNSIGNED: &[(ComponentType, bool)] =
    &[(ComponentType::U8, false), (ComponentType::U16, false), (ComponentType::U32, false)];

/// The layout of one accessor element in a buffer.
#[derive(Clone, Copy)]
pub(super) struct ElementFormat {
    pub(super) component: ComponentType,
    pub(super) components: usize,
    pub(super) normalized: bool,
}

impl ElementFormat {
    fn size(self) -> usize {
        component_size(self.component) * self.components
    }
}

fn component_size(component: ComponentType) -> usize {
    match component {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn type_components(ty: Type) -> usize {
    match ty {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

pub(super) fn type_name(ty: Type) -> &'static str {
    match ty {
        Type::Scalar => "SCALAR",
        Type::Vec2 => "VEC2",
        Type::Vec3 => "VEC3",
        Type::Vec4 => "VEC4",
        Type::Mat2 => "MAT2",
        Type::Mat3 => "MAT3",
        Type::Mat4 => "MAT4",
    }
}

fn component_name(component: ComponentType) -> &'static str {
    match component {
        ComponentType::I8 => "BYTE",
        ComponentType::U8 => "UNSIGNED_BYTE",
        ComponentType::I16 => "SHORT",
        ComponentType::U16 => "UNSIGNED_SHORT",
        ComponentType::U32 => "UNSIGNED_INT",
        ComponentType::F32 => "FLOAT",
    }
}

/// Component `i` of an element, as f32 (normalized integers mapped to [0, 1] / [-1, 1]).
fn component_f32(bytes: &[u8], format: ElementFormat, i: usize) -> Option<f32> {
    let size = component_size(format.component);
    let at = i.checked_mul(size)?;
    let raw = bytes.get(at..at.checked_add(size)?)?;
    let norm = format.normalized;
    Some(match format.component {
        ComponentType::F32 => f32::from_le_bytes(raw.try_into().ok()?),
        ComponentType::U8 => {
            let v = f32::from(*raw.first()?);
            if norm { v / 255.0 } else { v }
        }
        ComponentType::I8 => {
            let v = f32::from(i8::from_le_bytes(raw.try_into().ok()?));
            if norm { (v / 127.0).max(-1.0) } else { v }
        }
        ComponentType::U16 => {
            let v = f32::from(u16::from_le_bytes(raw.try_into().ok()?));
            if norm { v / 65535.0 } else { v }
        }
        ComponentType::I16 => {
            let v = f32::from(i16::from_le_bytes(raw.try_into().ok()?));
            if norm { (v / 32767.0).max(-1.0) } else { v }
        }
        ComponentType::U32 => {
            let v = u32::from_le_bytes(raw.try_into().ok()?) as f32;
            if norm { v / u32::MAX as f32 } else { v }
        }
    })
}

fn index_value(bytes: &[u8], component: ComponentType) -> Option<u32> {
    match component {
        ComponentType::U8 => bytes.first().map(|&b| u32::from(b)),
        ComponentType::U16 => Some(u32::from(u16::from_le_bytes(bytes.get(0..2)?.try_into().ok()?))),
        ComponentType::U32 => Some(u32::from_le_bytes(bytes.get(0..4)?.try_into().ok()?)),
        _ => None,
    }
}

pub(super) fn decode_vec3(bytes: &[u8], format: ElementFormat) -> Option<[f32; 3]> {
    Some([component_f32(bytes, format, 0)?, component_f32(bytes, format, 1)?, component_f32(bytes, format, 2)?])
}

pub(super) fn decode_vec2(bytes: &[u8], format: ElementFormat) -> Option<[f32; 2]> {
    Some([component_f32(bytes, format, 0)?, component_f32(bytes, format, 1)?])
}

/// A COLOR_0 element as RGBA; a three-component element gets alpha 1.
pub(super) fn decode_color(bytes: &[u8], format: ElementFormat) -> Option<[f32; 4]> {
    let [r, g, b] = decode_vec3(bytes, format)?;
    let a = if format.components >= 4 { component_f32(bytes, format, 3)? } else { 1.0 };
    Some([r, g, b, a])
}

pub(super) fn decode_index(bytes: &[u8], format: ElementFormat) -> Option<u32> {
    index_value(bytes, format.component)
}

/// What an accessor must look like for one use.
pub(super) struct Expect {
    pub(super) purpose: String,
    pub(super) ty: Type,
    pub(super) components: &'static [(ComponentType, bool)],
}

impl Importer<'_, '_> {
    fn charge(&self, bytes: u64, what: &str) -> Result<(), Fail> {
        let left = self.budget.get();
        if bytes > left {
            return invalid(format!("{what} needs {bytes} bytes of memory, more than the file's size justifies"));
        }
        self.budget.set(left - bytes);
        Ok(())
    }

    /// The bytes of buffer `index`, loaded on first use (which raises the memory budget
    /// by what the buffer's size justifies).
    fn buffer(&self, index: usize, what: &str) -> Result<&[u8], Fail> {
        let Some(cell) = self.buffers.get(index) else {
            return invalid(format!("{what}: buffer {index} does not exist"));
        };
        if cell.get().is_none() {
            let data = load_buffer(self.root, index, self.bin, self.base_dir)?;
            let extra = (data.len() as u64).saturating_mul(BUDGET_PER_INPUT_BYTE);
            self.budget.set(self.budget.get().saturating_add(extra));
            let _ = cell.set(data);
        }
        match cell.get() {
            Some(data) => Ok(data.as_ref()),
            None => invalid(format!("{what}: buffer {index} could not be loaded")),
        }
    }

    /// The bytes of buffer view `index`, bounds-checked against its buffer.
    pub(super) fn view_bytes(&self, index: usize, what: &str) -> Result<(&[u8], Option<usize>), Fail> {
        let Some(view) = self.root.buffer_views.get(index) else {
            return invalid(format!("{what}: bufferView {index} does not exist"));
        };
        let buffer_index = view.buffer.value();
        let buffer = self.buffer(buffer_index, what)?;
        let offset = view.byte_offset.map_or(0, |o| o.0);
        let length = view.byte_length.0;
        let range =
            offset.checked_add(length).and_then(|end| Some(usize::try_from(offset).ok()?..usize::try_from(end).ok()?));
        let Some(bytes) = range.and_then(|range| buffer.get(range)) else {
            return invalid(format!(
                "{what}: bufferView {index} (offset {offset}, length {length}) lies outside buffer {buffer_index} ({} bytes)",
                buffer.len()
            ));
        };
        Ok((bytes, view.byte_stride.map(|s| s.0)))
    }

    /// Reads accessor `index` element by element with `decode`, applying sparse data.
    pub(super) fn read_accessor<T: Copy + Default>(
        &mut self,
        index: usize,
        expect: &Expect,
        decode: Decode<T>,
    ) -> Result<Vec<T>, Fail> {
        let root = self.root;
        let what = format!("{} (accessor {index})", expect.purpose);
        let Some(accessor) = root.accessors.get(index) else {
            return invalid(format!("{what}: accessor does not exist"));
        };
        let format = checked_format(accessor, expect, &what)?;
        let count_u64 = accessor.count.0;
        let Ok(count) = usize::try_from(count_u64) else {
            return invalid(format!("{what}: count {count_u64} is too large"));
        };
        let mut out: Vec<T> = if let Some(view_index) = accessor.buffer_view {
            self.read_view(accessor, view_index.value(), format, count, &what, decode)?
        } else {
            self.charge_elements::<T>(count, &what)?;
            vec![T::default(); count]
        };
        if let Some(sparse) = &accessor.sparse {
            self.apply_sparse(sparse, format, &mut out, &what, decode)?;
        }
        Ok(out)
    }

    /// Charges the budget for `count` decoded elements of type `T`.
    fn charge_elements<T>(&self, count: usize, what: &str) -> Result<(), Fail> {
        self.charge((count as u64).saturating_mul(std::mem::size_of::<T>() as u64), what)
    }

    /// The `count` elements of `accessor` stored in bufferView `view_index`.
    fn read_view<T>(
        &self,
        accessor: &json::Accessor,
        view_index: usize,
        format: ElementFormat,
        count: usize,
        what: &str,
        decode: Decode<T>,
    ) -> Result<Vec<T>, Fail> {
        let element_size = format.size();
        let (bytes, stride) = self.view_bytes(view_index, what)?;
        let stride = stride.unwrap_or(element_size);
        if stride < element_size {
            return invalid(format!("{what}: byteStride {stride} is smaller than the element size {element_size}"));
        }
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        let needed = if count == 0 {
            Some(0)
        } else {
            (count as u64 - 1)
                .checked_mul(stride as u64)
                .and_then(|v| v.checked_add(element_size as u64))
                .and_then(|v| v.checked_add(offset))
        };
        if needed.is_none_or(|n| n > bytes.len() as u64) {
            return invalid(format!(
                "{what}: {count} elements at offset {offset} with stride {stride} lie outside bufferView {view_index} ({} bytes): data out of bounds",
                bytes.len()
            ));
        }
        self.charge_elements::<T>(count, what)?;
        let offset = usize::try_from(offset).unwrap_or(usize::MAX);
        let mut out = Vec::with_capacity(count);
        for k in 0..count {
            let element = k
                .checked_mul(stride)
                .and_then(|start| start.checked_add(offset))
                .and_then(|start| bytes.get(start..start.checked_add(element_size)?))
                .and_then(|element| decode(element, format));
            let Some(value) = element else {
                return invalid(format!("{what}: element {k} cannot be read"));
            };
            out.push(value);
        }
        Ok(out)
    }

    /// Overwrites the elements that `sparse` names.
    fn apply_sparse<T>(
        &self,
        sparse: &json::accessor::sparse::Sparse,
        format: ElementFormat,
        out: &mut [T],
        what: &str,
        decode: Decode<T>,
    ) -> Result<(), Fail> {
        let count = out.len();
        let element_size = format.size();
        let sparse_count_u64 = sparse.count.0;
        let Some(sparse_count) = usize::try_from(sparse_count_u64).ok().filter(|&c| c <= count) else {
            return invalid(format!("{what}: sparse count {sparse_count_u64} exceeds the accessor count {count}"));
        };
        let Checked::Valid(index_type) = sparse.indices.component_type else {
            return invalid(format!("{what}: invalid sparse index componentType"));
        };
        let index_size = component_size(index_type.0);
        let (index_bytes, _) = self.view_bytes(sparse.indices.buffer_view.value(), what)?;
        let (value_bytes, _) = self.view_bytes(sparse.values.buffer_view.value(), what)?;
        let index_start = usize::try_from(sparse.indices.byte_offset.0).unwrap_or(usize::MAX);
        let value_start = usize::try_from(sparse.values.byte_offset.0).unwrap_or(usize::MAX);
        let index_slice = sparse_count
            .checked_mul(index_size)
            .and_then(|len| index_bytes.get(index_start..index_start.checked_add(len)?));
        let value_slice = sparse_count
            .checked_mul(element_size)
            .and_then(|len| value_bytes.get(value_start..value_start.checked_add(len)?));
        let (Some(index_slice), Some(value_slice)) = (index_slice, value_slice) else {
            return invalid(format!("{what}: sparse data lies outside its bufferView"));
        };
        for (k, (raw_index, raw_value)) in
            index_slice.chunks_exact(index_size).zip(value_slice.chunks_exact(element_size)).enumerate()
        {
            let target = index_value(raw_index, index_type.0).map(|i| i as usize);
            let value = decode(raw_value, format);
            let slot = target.and_then(|t| out.get_mut(t));
            let (Some(slot), Some(value)) = (slot, value) else {
                return invalid(format!("{what}: sparse element {k} has an index out of range or unreadable data"));
            };
            *slot = value;
        }
        Ok(())
    }
}

/// The element format of `accessor`, refused unless it has the type and one of the
/// component types that `expect` allows.
fn checked_format(accessor: &json::Accessor, expect: &Expect, what: &str) -> Result<ElementFormat, Fail> {
    let (Checked::Valid(ty), Checked::Valid(component)) = (accessor.type_, accessor.component_type) else {
        return invalid(format!("{what}: invalid type or componentType"));
    };
    let component = component.0;
    let allowed = expect.components.iter().any(|&(c, normalized)| c == component && normalized == accessor.normalized);
    if ty != expect.ty || !allowed {
        let allowed_names: Vec<String> = expect
            .components
            .iter()
            .map(|&(c, n)| format!("{}{}", component_name(c), if n { " normalized" } else { "" }))
            .collect();
        return invalid(format!(
            "{what}: wrong accessor type {} {}{} (expected {} of {})",
            type_name(ty),
            component_name(component),
            if accessor.normalized { " normalized" } else { "" },
            type_name(expect.ty),
            allowed_names.join(" or ")
        ));
    }
    Ok(ElementFormat { component, components: type_components(ty), normalized: accessor.normalized })
}
