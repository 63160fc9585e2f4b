//! Animated PNG (APNG) output: `forest render --animate` writes the wind's frames into one
//! file, which browsers, GitHub's Markdown and most image viewers play. The png crate's
//! encoder (already the image crate's) writes it; a still PNG reader shows the first frame.

use std::path::Path;

use anyhow::Result;

/// Write `frames` frames of `size` (pixels) `step` seconds apart, frame `i` drawn by
/// `frame(i)`, as an APNG that loops for ever, to `out` atomically (a temporary name, then a
/// rename: nothing half-written is left). Each frame is encoded as it comes.
pub fn write_apng(
    out: &Path,
    size: (u32, u32),
    frames: u32,
    step: f32,
    mut frame: impl FnMut(u32) -> Result<image::RgbaImage>,
) -> Result<()> {
    // The delay as a fraction of a second (APNG stores 16-bit numerator and denominator).
    let delay_ms = (step * 1000.0).round().clamp(1.0, f32::from(u16::MAX)) as u16;
    forest_format::atomic::write_with(out, |tmp| -> Result<(), String> {
        let mut write = || -> Result<()> {
            let file = std::io::BufWriter::new(std::fs::File::create(tmp)?);
            let mut enc = png::Encoder::new(file, size.0, size.1);
            enc.set_color(png::ColorType::Rgba);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_animated(frames, 0)?;
            enc.set_frame_delay(delay_ms, 1000)?;
            let mut writer = enc.write_header()?;
            for i in 0..frames {
                let img = frame(i)?;
                anyhow::ensure!(
                    img.dimensions() == size,
                    "frame {i} is {}x{}, not {}x{}",
                    img.width(),
                    img.height(),
                    size.0,
                    size.1
                );
                writer.write_image_data(img.as_raw())?;
            }
            writer.finish()?;
            Ok(())
        };
        write().map_err(|e| format!("{e:#}"))
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    /// Frames written are read back as an animation of the same frames and delays.
    #[test]
    fn frames_come_back_in_order_with_their_delay() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("a.png");
        let frame =
            |i: u32| image::RgbaImage::from_pixel(4, 3, image::Rgba([i as u8 * 40, 7, 9, 255]));
        super::write_apng(&out, (4, 3), 5, 1.0 / 15.0, |i| Ok(frame(i))).unwrap();
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&out).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let control = reader.info().animation_control().copied().unwrap();
        assert_eq!((control.num_frames, control.num_plays), (5, 0));
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        for i in 0..5 {
            reader.next_frame(&mut buf).unwrap();
            let fc = reader.info().frame_control().copied().unwrap();
            assert_eq!((fc.delay_num, fc.delay_den), (67, 1000));
            assert_eq!(&buf[..4], frame(i).as_raw()[..4].as_ref(), "frame {i}");
        }
        // Only the file: no temporary is left.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // A frame of another size is refused, and nothing is left behind.
        let bad = dir.path().join("b.png");
        let e = super::write_apng(&bad, (4, 3), 2, 0.1, |i| {
            Ok(image::RgbaImage::new(4 + i, 3))
        })
        .unwrap_err();
        assert!(format!("{e:#}").contains("frame 1 is 5x3"), "{e:#}");
        assert!(!bad.exists());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
