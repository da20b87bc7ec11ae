//! Pictures as files: the format asked for by a file name, SVG and PNG drawn into a staged
//! temporary file and put in place atomically, animated GIFs the same way; drawing errors said
//! as people read them.

use std::error::Error;
use std::io::Write as _;
use std::path::Path;

use image::ImageEncoder as _;
use kinergy_io::AtomicFile;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters_backend::DrawingErrorKind;

use crate::{DrawError, DrawResult, Figure, register_fonts};

/// The picture formats, from the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics.
    Svg,
    /// A PNG bitmap.
    Png,
}

impl Format {
    /// The format `path` asks for by its extension (`.svg` or `.png`).
    pub fn of(path: &Path) -> Result<Format, DrawError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(DrawError::Format {
                path: path.to_path_buf(),
            }),
        }
    }
}

/// A drawing failure writing the picture `path`, said without Rust's Debug text.
fn drawing_failed(path: &Path, e: &(dyn Error + 'static)) -> DrawError {
    DrawError::drawing(path, plain(e))
}

/// The bitmap backend's error type (plotters does not export its name).
type BitmapError = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

/// A drawing error as people read it. plotters' bitmap backend displays its errors with
/// Rust's Debug formatting (`IOError(Os { code: 28, kind: StorageFull, … })`): say the I/O
/// error inside instead.
fn plain(e: &(dyn Error + 'static)) -> String {
    let bitmap = e.downcast_ref::<BitmapError>().or_else(|| {
        match e.downcast_ref::<DrawingAreaErrorKind<BitmapError>>() {
            Some(DrawingAreaErrorKind::BackendError(DrawingErrorKind::DrawingError(b))) => Some(b),
            _ => None,
        }
    });
    match bitmap {
        Some(BitmapError::IOError(io)) => io.to_string(),
        Some(BitmapError::InvalidBuffer) => "the picture's pixel buffer has the wrong size".into(),
        Some(other) => other.source().map_or_else(
            || "the picture could not be encoded".into(),
            |s| s.to_string(),
        ),
        None => e.to_string(),
    }
}

/// Starts the staged file of the picture `path`.
fn start(path: &Path) -> Result<AtomicFile, DrawError> {
    AtomicFile::create(path).map_err(|e| DrawError::io(path, e))
}

/// Puts a staged picture in place.
pub fn commit(staged: AtomicFile) -> Result<(), DrawError> {
    let path = staged.path().to_path_buf();
    staged.commit().map_err(|e| DrawError::io(&path, e))
}

/// Draws `figure` for `path` (SVG or PNG by its extension) into a temporary file beside it,
/// not yet in place: [`commit`] it, or drop it to leave `path` as it was.
pub fn stage(figure: &impl Figure, path: &Path, size: (u32, u32)) -> Result<AtomicFile, DrawError> {
    register_fonts();
    let format = Format::of(path)?;
    let bytes = match format {
        Format::Svg => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
                figure
                    .draw(&root)
                    .and_then(|()| root.present().map_err(|e| e.into()))
                    .map_err(|e| drawing_failed(path, &*e))?;
            }
            text.into_bytes()
        }
        Format::Png => {
            // Rendered in memory, encoded into the staged file: no encoder writes the path.
            let pixels = usize::try_from(u64::from(size.0) * u64::from(size.1) * 3)
                .map_err(|e| DrawError::drawing(path, e))?;
            let mut rgb = vec![0u8; pixels];
            {
                let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
                figure
                    .draw(&root)
                    .and_then(|()| root.present().map_err(|e| e.into()))
                    .map_err(|e| drawing_failed(path, &*e))?;
            }
            let mut png = Vec::new();
            image::codecs::png::PngEncoder::new(&mut png)
                .write_image(&rgb, size.0, size.1, image::ColorType::Rgb8)
                .map_err(|e| DrawError::drawing(path, e))?;
            png
        }
    };
    let mut staged = start(path)?;
    staged
        .write_all(&bytes)
        .map_err(|e| DrawError::io(path, e))?;
    Ok(staged)
}

/// Draws `figure` into `path` (SVG or PNG by its extension), written atomically.
pub fn save(figure: &impl Figure, path: &Path, size: (u32, u32)) -> Result<(), DrawError> {
    commit(stage(figure, path, size)?)
}

/// Saves `figure` as `DIR/name.svg` and `DIR/name.png`.
pub fn save_both(
    figure: &impl Figure,
    dir: &Path,
    name: &str,
    size: (u32, u32),
) -> Result<(), DrawError> {
    for ext in ["svg", "png"] {
        save(figure, &dir.join(format!("{name}.{ext}")), size)?;
    }
    Ok(())
}

/// Draws `frames` frames of an animated GIF for `path` (`delay_ms` per frame) into a
/// temporary file beside it, not yet in place (see [`stage`]); `frame(k, root)` draws frame
/// `k`.
pub fn stage_gif(
    path: &Path,
    size: (u32, u32),
    frames: usize,
    delay_ms: u32,
    frame: impl Fn(usize, &DrawingArea<BitMapBackend<'_>, Shift>) -> DrawResult,
) -> Result<AtomicFile, DrawError> {
    register_fonts();
    let staged = start(path)?;
    // The GIF encoder writes a path: it truncates and fills the staged temporary file.
    (|| -> DrawResult {
        let root = BitMapBackend::gif(staged.temp_path(), size, delay_ms)?.into_drawing_area();
        for k in 0..frames {
            frame(k, &root)?;
            root.present()?;
        }
        Ok(())
    })()
    .map_err(|e| drawing_failed(path, &*e))?;
    Ok(staged)
}

#[cfg(test)]
mod tests {
    use super::{BitmapError, plain};
    use plotters::prelude::DrawingAreaErrorKind;
    use plotters_backend::DrawingErrorKind;

    #[test]
    fn a_full_disk_while_drawing_is_said_without_debug_text() {
        let io = || std::io::Error::from(std::io::ErrorKind::StorageFull);
        let direct: Box<dyn std::error::Error> = Box::new(BitmapError::IOError(io()));
        let wrapped: Box<dyn std::error::Error> = Box::new(DrawingAreaErrorKind::BackendError(
            DrawingErrorKind::DrawingError(BitmapError::IOError(io())),
        ));
        for e in [direct, wrapped] {
            let text = plain(&*e);
            assert!(
                !text.contains("IOError") && !text.contains("kind:"),
                "{text}"
            );
            assert_eq!(text, io().to_string());
        }
    }
}
