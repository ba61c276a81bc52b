//! The files a scene reads (scene text, textures, spectral sets, the star
//! catalogue, meshes): from the file system, or in the browser from the
//! files the page fetched over HTTP and registered here under their paths
//! on the site ([`insert`]). Everything that reads a scene's input goes
//! through these functions, so the same loader serves both.

use std::io;
use std::path::Path;

#[cfg(target_arch = "wasm32")]
mod fetched {
    use std::collections::HashMap;
    use std::path::{Path, PathBuf};
    use std::sync::{Arc, Mutex};

    static FILES: Mutex<Option<HashMap<PathBuf, Arc<[u8]>>>> = Mutex::new(None);

    pub fn insert(path: &Path, bytes: Vec<u8>) {
        FILES
            .lock()
            .expect("fetched files")
            .get_or_insert_with(HashMap::new)
            .insert(path.to_path_buf(), bytes.into());
    }

    pub fn get(path: &Path) -> Option<Arc<[u8]>> {
        FILES
            .lock()
            .expect("fetched files")
            .as_ref()?
            .get(path)
            .cloned()
    }
}

/// Registers the bytes of `path` (a path on the site, from its root), as
/// the page fetched them.
#[cfg(target_arch = "wasm32")]
pub fn insert(path: &Path, bytes: Vec<u8>) {
    fetched::insert(path, bytes)
}

/// Whether `path` has been fetched.
#[cfg(target_arch = "wasm32")]
pub fn fetched(path: &Path) -> bool {
    fetched::get(path).is_some()
}

/// The fetched bytes of `path`, or why there are none.
#[cfg(target_arch = "wasm32")]
fn fetched_bytes(path: &Path) -> io::Result<std::sync::Arc<[u8]>> {
    fetched::get(path).ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::NotFound,
            "not on the site (the page fetches the files the scene names)",
        )
    })
}

/// The bytes of `path`.
pub fn read(path: &Path) -> io::Result<Vec<u8>> {
    #[cfg(not(target_arch = "wasm32"))]
    return std::fs::read(path);
    #[cfg(target_arch = "wasm32")]
    fetched_bytes(path).map(|b| b.to_vec())
}

/// The text of `path` (UTF-8).
pub fn read_to_string(path: &Path) -> io::Result<String> {
    #[cfg(not(target_arch = "wasm32"))]
    return std::fs::read_to_string(path);
    #[cfg(target_arch = "wasm32")]
    String::from_utf8(read(path)?).map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))
}

/// The size of `path` in bytes; None if it is not a regular file.
pub fn file_len(path: &Path) -> io::Result<Option<u64>> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        let meta = std::fs::metadata(path)?;
        Ok(meta.is_file().then_some(meta.len()))
    }
    #[cfg(target_arch = "wasm32")]
    Ok(Some(fetched_bytes(path)?.len() as u64))
}

/// An image reader for `path`, its format guessed from the content.
pub fn image_reader(path: &Path) -> io::Result<image::ImageReader<impl io::BufRead + io::Seek>> {
    #[cfg(not(target_arch = "wasm32"))]
    let reader = image::ImageReader::open(path)?;
    #[cfg(target_arch = "wasm32")]
    let reader = image::ImageReader::new(io::Cursor::new(read(path)?));
    let reader = reader.with_guessed_format()?;
    // Else the decoder's own message quotes the extension oddly.
    if reader.format().is_none() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            "not an image: its content is none of PNG, JPEG, OpenEXR, Radiance HDR or GIF",
        ));
    }
    Ok(reader)
}
