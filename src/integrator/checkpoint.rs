//! The state of an unfinished render (`OUTPUT.state` beside a render's output), from which
//! `tessera render --resume` continues: the running sums of every pixel ([`Film::state`]) after
//! a number of whole samples per pixel, with what they were rendered from (a fingerprint of the
//! scene, the crop, the AOVs), so that the resumed render equals an uninterrupted one bit for
//! bit ([`super::render_samples`]).

use super::Crop;
use crate::error::{Error, Result};
use crate::image::{Aov, Film};
use std::path::Path;

/// The file's first bytes.
const MAGIC: &[u8; 16] = b"tessera-state-01";

/// An unfinished render.
#[derive(Clone, Debug)]
pub struct Checkpoint {
    /// What the render was made from (scene text, values set, settings but the sample count).
    pub fingerprint: u64,
    /// The pixels rendered.
    pub crop: Crop,
    /// Whole samples per pixel in the film.
    pub samples: u32,
    /// The running sums.
    pub film: Film,
}

/// FNV-1a of `bytes`: a fingerprint, the same on every platform and Rust version.
pub fn fingerprint(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

impl Checkpoint {
    /// Write it to `path`, atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&self.fingerprint.to_le_bytes());
        for v in [self.crop.x0, self.crop.y0, self.crop.x1, self.crop.y1, self.samples] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        bytes.extend_from_slice(&aov_code(self.film.aovs()).to_le_bytes());
        bytes.extend(self.film.state());
        crate::files::write_atomically(path, |tmp| std::fs::write(tmp, &bytes).map_err(|e| Error::io(path, e)))
    }

    /// Read the checkpoint at `path` made for `fingerprint`, `crop` and `aovs`: an error naming
    /// the file when it is not one, or was made for another scene, crop or AOVs.
    pub fn read(path: &Path, fingerprint: u64, crop: Crop, aovs: &[Aov]) -> Result<Checkpoint> {
        let (w, h) = crop.size();
        let expected = Film::new(w as usize, h as usize, aovs).state().len() + MAGIC.len() + 8 + 5 * 4 + 8;
        let bad = |msg: &str| Error::image(path, msg.to_string());
        let size = std::fs::metadata(path).map_err(|e| Error::io(path, e))?.len();
        if size != expected as u64 {
            return Err(bad("not the state of this render (its size differs: another crop, resolution or AOVs?)"));
        }
        let bytes = crate::files::read_bounded(path, expected as u64, "a render's state")?;
        if bytes.len() != expected || !bytes.starts_with(MAGIC) {
            return Err(bad(
                "not the state of this render (its size or kind differs: another crop, resolution or AOVs?)",
            ));
        }
        let u32_at = |k: usize| u32::from_le_bytes(bytes[k..k + 4].try_into().expect("4 bytes"));
        let u64_at = |k: usize| u64::from_le_bytes(bytes[k..k + 8].try_into().expect("8 bytes"));
        let at = MAGIC.len();
        if u64_at(at) != fingerprint {
            return Err(bad("made from another scene (its text, --set values, seed or settings differ)"));
        }
        let stored = Crop { x0: u32_at(at + 8), y0: u32_at(at + 12), x1: u32_at(at + 16), y1: u32_at(at + 20) };
        if stored != crop || u64_at(at + 28) != aov_code(aovs) {
            return Err(bad("made for another crop or other AOVs"));
        }
        let samples = u32_at(at + 24);
        let film = Film::from_state(w as usize, h as usize, aovs, &bytes[at + 36..]).ok_or_else(|| bad("damaged"))?;
        if film.samples_per_pixel() != Some(samples) {
            return Err(bad("damaged: its pixels do not all hold the samples it says"));
        }
        Ok(Checkpoint { fingerprint, crop, samples, film })
    }
}

/// The AOVs as a number (their channel names, fingerprinted).
fn aov_code(aovs: &[Aov]) -> u64 {
    fingerprint(
        aovs.iter().flat_map(|a| a.channel_names()).flat_map(|n| n.bytes().chain([0])).collect::<Vec<u8>>().as_slice(),
    )
}
