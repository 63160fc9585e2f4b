//! Bounded file reads: every file the project reads from a user is checked to be a regular
//! file no larger than a limit before a byte is read, and read through a reader that stops at
//! the limit (for files whose size lies, such as those under /proc). An OBJ whose `mtllib`
//! names /dev/zero is refused instead of read until memory runs out.

use std::io::Read;
use std::path::Path;

use crate::error::FormatError;

/// Limits (bytes) of the files the project reads.
pub mod limit {
    /// An atlas manifest, a camera path, a material library.
    pub const TEXT: u64 = 64 << 20;
    /// An OBJ model, a forest file, an atlas mosaic or node file, an image.
    pub const DATA: u64 = 4 << 30;
    /// A texture of a model.
    pub const TEXTURE: u64 = 1 << 30;
    /// The widest and tallest image decoded (pixels): textures, atlas mosaics, images given
    /// to `compare`.
    pub const IMAGE_SIDE: u32 = 16_384;
    /// The most bytes a decoder may allocate for one image's pixels.
    pub const IMAGE_ALLOC: u64 = 512 << 20;
}

fn image_reader<'a>(
    bytes: &'a [u8],
    format: Option<image::ImageFormat>,
    path: &Path,
) -> Result<image::ImageReader<std::io::Cursor<&'a [u8]>>, FormatError> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
    match format {
        Some(f) => reader.set_format(f),
        None => {
            reader = reader
                .with_guessed_format()
                .map_err(|e| FormatError::Image {
                    path: path.into(),
                    what: e.to_string(),
                })?
        }
    }
    Ok(reader)
}

/// The width and height (pixels) an encoded image's header claims, read without decoding its
/// pixels: sizes that must agree with other counts are compared before anything is decoded.
pub fn image_dimensions(
    bytes: &[u8],
    format: Option<image::ImageFormat>,
    path: &Path,
) -> Result<(u32, u32), FormatError> {
    image_reader(bytes, format, path)?
        .into_dimensions()
        .map_err(|e| FormatError::Image {
            path: path.into(),
            what: e.to_string(),
        })
}

/// Refuse a PNG whose palette chunk (PLTE) is not a whole number of RGB entries, as the PNG
/// specification requires: png 0.18.1 panics on one (image-rs/image-png#694). Other chunks
/// are the decoder's to check.
fn check_png_chunks(bytes: &[u8]) -> Result<(), String> {
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    let Some(mut rest) = bytes.strip_prefix(SIGNATURE) else {
        return Ok(());
    };
    while rest.len() >= 8 {
        let len = u32::from_be_bytes(rest[..4].try_into().expect("4 bytes")) as usize;
        let kind = &rest[4..8];
        if kind == b"PLTE" && !len.is_multiple_of(3) {
            return Err(format!(
                "PNG palette chunk of {len} bytes, not a multiple of 3 (RGB entries)"
            ));
        }
        if kind == b"IDAT" || kind == b"IEND" {
            break;
        }
        // Length, type, data, CRC.
        rest = rest.get(12usize.saturating_add(len)..).unwrap_or(&[]);
    }
    Ok(())
}

/// Decode an image held in memory (`format` when the container is known, else guessed from
/// its first bytes) with the sizes bounded by [`limit::IMAGE_SIDE`] and
/// [`limit::IMAGE_ALLOC`], checked from the header before the pixels are allocated. Errors
/// name `path`, the file the bytes came from.
pub fn decode_image(
    bytes: &[u8],
    format: Option<image::ImageFormat>,
    path: &Path,
) -> Result<image::DynamicImage, FormatError> {
    let err = |what: String| FormatError::Image {
        path: path.into(),
        what,
    };
    check_png_chunks(bytes).map_err(err)?;
    let mut reader = image_reader(bytes, format, path)?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(limit::IMAGE_SIDE);
    limits.max_image_height = Some(limit::IMAGE_SIDE);
    limits.max_alloc = Some(limit::IMAGE_ALLOC);
    reader.limits(limits);
    reader.decode().map_err(|e| {
        err(match e {
            image::ImageError::Limits(_) => format!(
                "larger than the {side}×{side} pixels or {mb} MB of pixels read from one image",
                side = limit::IMAGE_SIDE,
                mb = limit::IMAGE_ALLOC >> 20
            ),
            other => other.to_string(),
        })
    })
}

/// Read `path` whole when it is a regular file of at most `limit` bytes; the error names the
/// file and the cause.
pub fn read(path: &Path, limit: u64) -> Result<Vec<u8>, FormatError> {
    let meta = std::fs::metadata(path).map_err(|e| FormatError::io(path, e))?;
    if !meta.is_file() {
        return Err(FormatError::invalid(
            path,
            "is not a regular file (a folder, device or pipe): refusing to read it",
        ));
    }
    if meta.len() > limit {
        return Err(FormatError::invalid(
            path,
            format!("{} bytes, more than the {limit}-byte limit", meta.len()),
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| FormatError::io(path, e))?;
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| FormatError::io(path, e))?;
    if bytes.len() as u64 > limit {
        return Err(FormatError::invalid(
            path,
            format!("grew past the {limit}-byte limit while being read"),
        ));
    }
    Ok(bytes)
}

/// [`read`] as UTF-8 text.
pub fn read_text(path: &Path, limit: u64) -> Result<String, FormatError> {
    String::from_utf8(read(path, limit)?)
        .map_err(|_| FormatError::invalid(path, "is not UTF-8 text"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_are_checked_before_decoding() {
        // A PNG whose palette is not whole RGB entries (png 0.18.1 panics on it).
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        png.extend_from_slice(&13u32.to_be_bytes());
        png.extend_from_slice(b"IHDR");
        png.extend_from_slice(&[0, 0, 0, 1, 0, 0, 0, 1, 8, 3, 0, 0, 0, 0, 0, 0, 0]);
        png.extend_from_slice(&4u32.to_be_bytes());
        png.extend_from_slice(b"PLTE\x01\x02\x03\x04\0\0\0\0");
        let e = decode_image(&png, None, Path::new("p.png")).unwrap_err();
        assert!(e.to_string().contains("not a multiple of 3"), "{e}");
        // Sizes come from the header alone.
        let img = image::RgbImage::new(40, 3);
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
        let bytes = bytes.into_inner();
        assert_eq!(
            image_dimensions(&bytes, None, Path::new("i.png")).unwrap(),
            (40, 3)
        );
    }

    #[test]
    fn special_and_oversized_files_are_refused_before_reading() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.bin");
        std::fs::write(&f, [7u8; 100]).unwrap();
        assert_eq!(read(&f, 100).unwrap().len(), 100);
        assert!(read(&f, 99).unwrap_err().to_string().contains("limit"));
        assert!(
            read(dir.path(), 1 << 20)
                .unwrap_err()
                .to_string()
                .contains("regular file")
        );
        if Path::new("/dev/zero").exists() {
            let e = read(Path::new("/dev/zero"), 1 << 20)
                .unwrap_err()
                .to_string();
            assert!(e.contains("regular file"), "{e}");
        }
        assert!(read(&dir.path().join("none"), 10).is_err());
    }
}
