//! Frames on disk: binary PGM (`P5`, maxval 255, 8-bit grey, row-major, top row first),
//! read and written with the `image` crate.

use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use image::codecs::pnm::{PnmDecoder, PnmEncoder, PnmSubtype, SampleEncoding};
use image::{ExtendedColorType, GrayImage, ImageDecoder};

/// Width and height (px) from a PGM's header, after checking that it is binary `P5` with
/// maxval 255. Reads the header only.
pub fn read_pgm_size(path: &Path) -> Result<(u32, u32)> {
    let decoder = open_decoder(path)?;
    Ok(decoder.dimensions())
}

/// Reads a binary 8-bit PGM (`P5`, maxval 255).
pub fn read_pgm(path: &Path) -> Result<GrayImage> {
    read_pgm_checked(path, |_| Ok(()))
}

/// Reads a binary 8-bit PGM after `check` has accepted its width and height (px), so a
/// header announcing a huge image is refused before any pixel memory is allocated.
pub fn read_pgm_checked(
    path: &Path,
    check: impl FnOnce((u32, u32)) -> Result<()>,
) -> Result<GrayImage> {
    let decoder = open_decoder(path)?;
    let (width, height) = decoder.dimensions();
    check((width, height))?;
    let mut pixels = vec![0u8; decoder.total_bytes() as usize];
    decoder
        .read_image(&mut pixels)
        .map_err(|e| anyhow!("{}: cannot read the pixels: {e}", path.display()))?;
    GrayImage::from_raw(width, height, pixels)
        .with_context(|| format!("{}: pixel data does not fill the image", path.display()))
}

/// Writes `image` as a binary PGM (`P5`, maxval 255).
pub fn write_pgm(path: &Path, image: &GrayImage) -> Result<()> {
    let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
    let mut out = BufWriter::new(file);
    PnmEncoder::new(&mut out)
        .with_subtype(PnmSubtype::Graymap(SampleEncoding::Binary))
        .encode(
            image.as_raw().as_slice(),
            image.width(),
            image.height(),
            ExtendedColorType::L8,
        )
        .with_context(|| format!("cannot write {}", path.display()))?;
    out.flush()
        .with_context(|| format!("cannot write {}", path.display()))
}

fn open_decoder(path: &Path) -> Result<PnmDecoder<BufReader<File>>> {
    let file = File::open(path).with_context(|| format!("cannot open {}", path.display()))?;
    // The `image` crate's errors already say what their source says: shown once, not chained
    // (a chain would print the cause twice).
    let decoder = PnmDecoder::new(BufReader::new(file))
        .map_err(|e| anyhow!("{}: not a readable PGM file: {e}", path.display()))?;
    let header = decoder.header();
    if header.subtype() != PnmSubtype::Graymap(SampleEncoding::Binary) {
        bail!(
            "{}: not a binary PGM (P5); frames must be 8-bit grey P5",
            path.display()
        );
    }
    if header.maximal_sample() != 255 {
        bail!(
            "{}: maxval is {}, frames must have maxval 255",
            path.display(),
            header.maximal_sample()
        );
    }
    Ok(decoder)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_keeps_every_pixel() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.pgm");
        let image = GrayImage::from_fn(7, 5, |x, y| image::Luma([(x * 31 + y * 17) as u8]));
        write_pgm(&path, &image).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"P5"));
        assert_eq!(bytes.len(), "P5\n7 5\n255\n".len() + 35);
        assert_eq!(read_pgm_size(&path).unwrap(), (7, 5));
        assert_eq!(read_pgm(&path).unwrap(), image);
    }

    #[test]
    fn ascii_pgm_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.pgm");
        std::fs::write(&path, "P2\n2 1\n255\n0 255\n").unwrap();
        let err = format!("{:#}", read_pgm(&path).unwrap_err());
        assert!(err.contains("P5") && err.contains("a.pgm"), "{err}");
    }

    #[test]
    fn sixteen_bit_pgm_is_rejected() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.pgm");
        std::fs::write(&path, b"P5\n1 1\n65535\n\x00\x01").unwrap();
        let err = format!("{:#}", read_pgm(&path).unwrap_err());
        assert!(err.contains("maxval"), "{err}");
    }

    #[test]
    fn truncated_pgm_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.pgm");
        std::fs::write(&path, b"P5\n4 4\n255\n\x00\x01").unwrap();
        assert!(read_pgm(&path).is_err());
    }
}
