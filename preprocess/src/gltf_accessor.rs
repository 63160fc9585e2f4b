//! Reading a glTF accessor's elements with every bound checked before a byte is read or a
//! vector sized: the buffer view inside its buffer, the accessor's first and last element
//! inside its view, the view's stride at least an element, the component type and the
//! normalised flag those glTF allows for the attribute. The gltf crate's own reader asserts
//! some of these (a stride below the element size panics) and quietly cuts a read short at a
//! buffer's end; this one names the accessor and what is wrong instead.
//!
//! Elements may sit at any byte offset (they are read byte by byte, little-endian), so a file
//! that breaks only glTF's alignment rule still loads. An accessor without a buffer view is
//! all zeros, as the specification says. Sparse accessors are refused by the caller.

use gltf::accessor::{DataType, Dimensions};

/// Bytes of one component.
fn component_bytes(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// Components of an element.
fn components(d: Dimensions) -> usize {
    match d {
        Dimensions::Scalar => 1,
        Dimensions::Vec2 => 2,
        Dimensions::Vec3 => 3,
        Dimensions::Vec4 | Dimensions::Mat2 => 4,
        Dimensions::Mat3 => 9,
        Dimensions::Mat4 => 16,
    }
}

/// Where an accessor's elements lie, checked against its view and buffer.
struct Layout<'a> {
    /// The view's bytes (None: no view, every element zero).
    view: Option<&'a [u8]>,
    /// Offset of element 0 in the view.
    offset: usize,
    /// Bytes from one element to the next.
    stride: usize,
    /// Elements.
    count: usize,
    /// Component type.
    data_type: DataType,
}

/// The layout of accessor `a` (named `name` in errors) over `buffers`, every bound checked;
/// `packed` requires a tightly packed view (index data may not be strided). `max_bytes`
/// bounds what the caller will allocate for it (4 bytes per component).
fn layout<'a>(
    a: &gltf::Accessor,
    buffers: &'a [std::borrow::Cow<[u8]>],
    name: &str,
    packed: bool,
    max_bytes: u64,
) -> Result<Layout<'a>, String> {
    let data_type = a.data_type();
    let width = components(a.dimensions());
    let element = component_bytes(data_type) * width;
    let count = a.count();
    if count == 0 {
        return Err(format!("{name} has count 0 (glTF requires at least 1)"));
    }
    if (count as u64).saturating_mul(4 * width as u64) > max_bytes {
        return Err(format!(
            "{name} has {count} elements, more than the {} bytes the loader reads",
            max_bytes
        ));
    }
    let Some(view) = a.view() else {
        return Ok(Layout {
            view: None,
            offset: 0,
            stride: element,
            count,
            data_type,
        });
    };
    let buffer = buffers.get(view.buffer().index()).ok_or_else(|| {
        format!(
            "{name}: its buffer view {} names buffer {}, which the file lacks",
            view.index(),
            view.buffer().index()
        )
    })?;
    let (start, length) = (view.offset(), view.length());
    let end = start
        .checked_add(length)
        .filter(|&e| e <= buffer.len())
        .ok_or_else(|| {
            format!(
                "{name}: its buffer view {} (bytes {start} + {length}) reaches past the {} \
                 bytes of buffer {}",
                view.index(),
                buffer.len(),
                view.buffer().index()
            )
        })?;
    let bytes = &buffer[start..end];
    let stride = match view.stride() {
        None => element,
        Some(s) if s < element => {
            return Err(format!(
                "{name}: its buffer view {} has byteStride {s}, smaller than its {element}-byte \
                 elements",
                view.index()
            ));
        }
        Some(s) if packed && s != element => {
            return Err(format!(
                "{name}: its buffer view {} has byteStride {s}; index data must be tightly \
                 packed",
                view.index()
            ));
        }
        Some(s) => s,
    };
    let offset = a.offset();
    let last = (count as u64 - 1)
        .checked_mul(stride as u64)
        .and_then(|x| x.checked_add(offset as u64))
        .and_then(|x| x.checked_add(element as u64));
    if last.is_none_or(|l| l > bytes.len() as u64) {
        return Err(format!(
            "{name}: {count} elements of {element} bytes every {stride} from byte {offset} \
             reach past the {} bytes of its buffer view {}",
            bytes.len(),
            view.index()
        ));
    }
    Ok(Layout {
        view: Some(bytes),
        offset,
        stride,
        count,
        data_type,
    })
}

/// Component `c` of element `i` as f32: floats as they are, normalised integers to [0, 1]
/// (unsigned) or [−1, 1] (signed), other integers as their value.
fn component(l: &Layout, i: usize, c: usize, normalized: bool) -> f32 {
    let Some(view) = l.view else { return 0.0 };
    let size = component_bytes(l.data_type);
    let at = l.offset + i * l.stride + c * size;
    let b = &view[at..at + size];
    match l.data_type {
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::U8 if normalized => f32::from(b[0]) / 255.0,
        DataType::U16 if normalized => f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        DataType::I8 if normalized => (f32::from(b[0] as i8) / 127.0).max(-1.0),
        DataType::I16 if normalized => {
            (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
        }
        DataType::U8 => f32::from(b[0]),
        DataType::U16 => f32::from(u16::from_le_bytes([b[0], b[1]])),
        DataType::I8 => f32::from(b[0] as i8),
        DataType::I16 => f32::from(i16::from_le_bytes([b[0], b[1]])),
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f32,
    }
}

/// The elements of a float attribute of `N` components (POSITION, NORMAL: f32; TEXCOORD_n:
/// f32, or normalised u8/u16), each finite. `allowed` lists the component types glTF permits
/// for it; integer types must be normalised, floats must not be.
pub fn read_floats<const N: usize>(
    a: &gltf::Accessor,
    buffers: &[std::borrow::Cow<[u8]>],
    name: &str,
    allowed: &[DataType],
    max_bytes: u64,
) -> Result<Vec<[f32; N]>, String> {
    check_type(a, name, allowed, N)?;
    let float = a.data_type() == DataType::F32;
    if float == a.normalized() {
        return Err(format!(
            "{name} is {:?}{}; glTF requires float components unnormalised and integer ones \
             normalised",
            a.data_type(),
            if a.normalized() {
                " with normalized: true"
            } else {
                " without normalized: true"
            }
        ));
    }
    let l = layout(a, buffers, name, false, max_bytes)?;
    let mut out = Vec::with_capacity(l.count);
    for i in 0..l.count {
        let mut e = [0.0f32; N];
        for (c, x) in e.iter_mut().enumerate() {
            *x = component(&l, i, c, a.normalized());
        }
        if let Some(x) = e.iter().find(|x| !x.is_finite()) {
            return Err(format!(
                "{name}: element {i} holds {x}, which is not finite"
            ));
        }
        out.push(e);
    }
    Ok(out)
}

/// The elements of an index accessor (unsigned 8, 16 or 32 bits, scalar, unnormalised,
/// tightly packed).
pub fn read_indices(
    a: &gltf::Accessor,
    buffers: &[std::borrow::Cow<[u8]>],
    name: &str,
    max_bytes: u64,
) -> Result<Vec<u32>, String> {
    check_type(a, name, &[DataType::U8, DataType::U16, DataType::U32], 1)?;
    if a.normalized() {
        return Err(format!(
            "{name} has normalized: true, which glTF forbids for indices"
        ));
    }
    let l = layout(a, buffers, name, true, max_bytes)?;
    let Some(view) = l.view else {
        return Ok(vec![0; l.count]);
    };
    let size = component_bytes(l.data_type);
    Ok((0..l.count)
        .map(|i| {
            let b = &view[l.offset + i * l.stride..][..size];
            match size {
                1 => u32::from(b[0]),
                2 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
            }
        })
        .collect())
}

/// The accessor is not sparse and has `width` components of one of the `allowed` types.
fn check_type(
    a: &gltf::Accessor,
    name: &str,
    allowed: &[DataType],
    width: usize,
) -> Result<(), String> {
    if a.sparse().is_some() {
        return Err(format!(
            "{name} is a sparse accessor, which is not supported"
        ));
    }
    if !allowed.contains(&a.data_type()) || components(a.dimensions()) != width {
        let want = match width {
            1 => Dimensions::Scalar,
            2 => Dimensions::Vec2,
            3 => Dimensions::Vec3,
            _ => Dimensions::Vec4,
        };
        return Err(format!(
            "{name} is {:?} {:?}; glTF requires {want:?} of {allowed:?}",
            a.dimensions(),
            a.data_type()
        ));
    }
    Ok(())
}
