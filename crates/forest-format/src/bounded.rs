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

/// Refuse a JPEG cut short: the decoder fills what is missing with grey and says nothing.
/// The main image's entropy-coded data follows its last start-of-scan marker (FF DA) and
/// must be closed by an end-of-image marker (FF D9); neither pair can occur inside
/// entropy-coded data (0xFF is stuffed there), and bytes after the marker are allowed.
fn check_jpeg_end(bytes: &[u8]) -> Result<(), String> {
    if !bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        return Ok(());
    }
    let marker = |m: u8| move |w: &[u8]| w == [0xFF, m];
    let Some(scan) = bytes.windows(2).rposition(marker(0xDA)) else {
        return Err("JPEG without image data (no start-of-scan marker)".into());
    };
    if !bytes[scan..].windows(2).any(marker(0xD9)) {
        return Err(format!(
            "JPEG cut short: no end-of-image marker after its image data ({} bytes read)",
            bytes.len()
        ));
    }
    Ok(())
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
    check_jpeg_end(bytes).map_err(err)?;
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
        // A JPEG cut short anywhere after its header is refused; whole, or with bytes after
        // its end, it decodes.
        let img =
            image::RgbImage::from_fn(64, 48, |x, y| image::Rgb([x as u8 * 3, y as u8 * 5, 90]));
        let mut jpeg = std::io::Cursor::new(Vec::new());
        img.write_to(&mut jpeg, image::ImageFormat::Jpeg).unwrap();
        let jpeg = jpeg.into_inner();
        let p = Path::new("c.jpg");
        assert!(decode_image(&jpeg, Some(image::ImageFormat::Jpeg), p).is_ok());
        let mut trailed = jpeg.clone();
        trailed.extend_from_slice(b"trailing bytes");
        assert!(decode_image(&trailed, None, p).is_ok());
        for keep in [jpeg.len() / 4, jpeg.len() / 2, jpeg.len() - 1] {
            let e = decode_image(&jpeg[..keep], None, p)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("c.jpg") && e.contains("JPEG"),
                "{keep} bytes: {e}"
            );
        }
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
