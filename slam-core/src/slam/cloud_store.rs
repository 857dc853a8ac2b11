//! The keyframes' map clouds, held in memory or, past a number of the newest, in a file: a
//! long walk's keyframes then cost memory for their poses and registration points only, as a
//! long-term memory (RTAB-Map's working and long-term memory) keeps what it does not use often
//! on disk.

use std::borrow::Cow;
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::Point3;
use thiserror::Error;

use crate::cloud::PointCloud;
use crate::error::CloudError;

/// Why a keyframe's map cloud, or the map made from them, could not be had.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum KeyframeCloudError {
    /// The file the older clouds are kept in could not be made, written or read.
    #[error("the keyframe store {path} could not be {action}")]
    Store {
        /// The store's file.
        path: PathBuf,
        /// What was being done: "created", "written", "read".
        action: &'static str,
        /// The system's error.
        #[source]
        source: std::io::Error,
    },
    /// A cloud could not be made from them (a bad voxel size for the map).
    #[error(transparent)]
    Cloud(#[from] CloudError),
}

/// One keyframe's cloud: in memory, or where the file holds it.
enum Slot {
    Held(PointCloud),
    Stored {
        /// Byte offset in the file.
        offset: u64,
        /// Points.
        len: usize,
        /// Whether an intensity per point follows the positions.
        intensity: bool,
    },
}

/// The store's file, removed when the store is dropped.
struct StoreFile {
    file: File,
    path: PathBuf,
    end: u64,
}

impl Drop for StoreFile {
    fn drop(&mut self) {
        // Nothing to do about a file that cannot be removed; it lies in the folder the user chose.
        let _ = std::fs::remove_file(&self.path);
    }
}

/// The keyframes' map clouds, in keyframe order, and the file their registration points may go
/// to as well ([`Stash`]).
#[derive(Default)]
pub(super) struct KeyframeClouds {
    slots: Vec<Slot>,
    file: Option<StoreFile>,
    /// How many of the newest clouds stay in memory when a file is set.
    resident: usize,
    /// The first slot still held that may be written out (clouds go out oldest first).
    next_out: usize,
    /// The first keyframe whose registration points may still be held in memory.
    pub(super) sources_out: usize,
}

/// A keyframe's prepared points: in memory, or where the store's file holds them.
pub(super) enum Stash<T> {
    Held(T),
    Stored { offset: u64, len: usize },
}

/// A stashed value, borrowed when held, read back when stored.
pub(super) enum Loaded<'a, T> {
    Borrowed(&'a T),
    Owned(T),
}

impl<T> std::ops::Deref for Loaded<'_, T> {
    type Target = T;

    fn deref(&self) -> &T {
        match self {
            Loaded::Borrowed(t) => t,
            Loaded::Owned(t) => t,
        }
    }
}

/// Distinguishes the files of several engines in one process.
static STORE_COUNTER: AtomicU64 = AtomicU64::new(0);

impl KeyframeClouds {
    /// A store that keeps the newest `resident` clouds in memory and writes older ones to a new
    /// file in `dir` (removed when the store is dropped).
    pub(super) fn in_folder(dir: &Path, resident: usize) -> Result<Self, KeyframeCloudError> {
        let name = format!(
            "spot-nav-keyframes-{}-{}.bin",
            std::process::id(),
            STORE_COUNTER.fetch_add(1, Ordering::Relaxed)
        );
        let path = dir.join(name);
        let file = OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .open(&path)
            .map_err(|source| KeyframeCloudError::Store {
                path: path.clone(),
                action: "created",
                source,
            })?;
        Ok(Self {
            slots: Vec::new(),
            file: Some(StoreFile { file, path, end: 0 }),
            resident,
            next_out: 0,
            sources_out: 0,
        })
    }

    /// How many keyframes keep their clouds and points in memory, when the store has a file.
    pub(super) fn resident(&self) -> Option<usize> {
        self.file.as_ref().map(|_| self.resident)
    }

    /// Writes `bytes` to the end of the file; where they start. An error without a file.
    pub(super) fn write_bytes(&mut self, bytes: &[u8]) -> Result<u64, KeyframeCloudError> {
        let Some(file) = self.file.as_mut() else {
            return Err(KeyframeCloudError::Store {
                path: PathBuf::new(),
                action: "written (no file)",
                source: std::io::Error::from(std::io::ErrorKind::NotFound),
            });
        };
        let offset = file.end;
        file.file
            .seek(SeekFrom::Start(offset))
            .and_then(|_| file.file.write_all(bytes))
            .map_err(|source| KeyframeCloudError::Store {
                path: file.path.clone(),
                action: "written",
                source,
            })?;
        file.end += bytes.len() as u64;
        Ok(offset)
    }

    /// The `len` bytes written at `offset`.
    pub(super) fn read_bytes(
        &self,
        offset: u64,
        len: usize,
    ) -> Result<Vec<u8>, KeyframeCloudError> {
        let Some(file) = self.file.as_ref() else {
            return Err(KeyframeCloudError::Store {
                path: PathBuf::new(),
                action: "read (no file)",
                source: std::io::Error::from(std::io::ErrorKind::NotFound),
            });
        };
        let mut bytes = vec![0_u8; len];
        // Reads through a shared handle: `&File` is `Read + Seek`, the store stays `&self`.
        let mut handle = &file.file;
        handle
            .seek(SeekFrom::Start(offset))
            .and_then(|_| handle.read_exact(&mut bytes))
            .map_err(|source| KeyframeCloudError::Store {
                path: file.path.clone(),
                action: "read",
                source,
            })?;
        Ok(bytes)
    }

    /// The error for stored bytes a registrator does not take back.
    pub(super) fn not_restored(&self) -> KeyframeCloudError {
        KeyframeCloudError::Store {
            path: self
                .file
                .as_ref()
                .map(|f| f.path.clone())
                .unwrap_or_default(),
            action: "read as the registrator's points",
            source: std::io::Error::from(std::io::ErrorKind::InvalidData),
        }
    }

    /// Number of clouds.
    pub(super) fn len(&self) -> usize {
        self.slots.len()
    }

    /// How many clouds are held in memory.
    pub(super) fn held(&self) -> usize {
        self.slots
            .iter()
            .filter(|s| matches!(s, Slot::Held(_)))
            .count()
    }

    /// Adds the next keyframe's cloud; with a file, writes the oldest held ones out until no
    /// more than `resident` are held. A cloud that cannot be written stays in memory, and the
    /// error is returned for the engine to count.
    pub(super) fn push(&mut self, cloud: PointCloud) -> Result<(), KeyframeCloudError> {
        self.slots.push(Slot::Held(cloud));
        if self.file.is_none() {
            return Ok(());
        }
        while self.slots.len() - self.next_out > self.resident {
            let i = self.next_out;
            let Slot::Held(cloud) = &self.slots[i] else {
                self.next_out += 1;
                continue;
            };
            let (len, intensity) = (cloud.len(), cloud.intensity().is_some());
            let bytes = encode(cloud);
            let offset = self.write_bytes(&bytes)?;
            self.slots[i] = Slot::Stored {
                offset,
                len,
                intensity,
            };
            self.next_out += 1;
        }
        Ok(())
    }

    /// Cloud `i`: borrowed when held, read back when stored; `None` past the last.
    pub(super) fn get(&self, i: usize) -> Option<Result<Cow<'_, PointCloud>, KeyframeCloudError>> {
        Some(match self.slots.get(i)? {
            Slot::Held(cloud) => Ok(Cow::Borrowed(cloud)),
            &Slot::Stored {
                offset,
                len,
                intensity,
            } => self.read(offset, len, intensity).map(Cow::Owned),
        })
    }

    /// The cloud of `len` points (and intensities) written at `offset`.
    fn read(
        &self,
        offset: u64,
        len: usize,
        intensity: bool,
    ) -> Result<PointCloud, KeyframeCloudError> {
        let bytes = self.read_bytes(offset, len * if intensity { 16 } else { 12 })?;
        Ok(decode(&bytes, len, intensity)?)
    }
}

/// A cloud's positions (x, y, z as little-endian f32) then its intensities, when it has them.
fn encode(cloud: &PointCloud) -> Vec<u8> {
    let intensity = cloud.intensity();
    let mut bytes = Vec::with_capacity(cloud.len() * if intensity.is_some() { 16 } else { 12 });
    for p in cloud.points() {
        for v in [p.x, p.y, p.z] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    for v in intensity.into_iter().flatten() {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes
}

/// The cloud [`encode`] wrote.
fn decode(bytes: &[u8], len: usize, intensity: bool) -> Result<PointCloud, CloudError> {
    let value = |k: usize| {
        let b = &bytes[4 * k..4 * k + 4];
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    };
    let points = (0..len)
        .map(|i| Point3::new(value(3 * i), value(3 * i + 1), value(3 * i + 2)))
        .collect();
    let cloud = PointCloud::from_points(points);
    if intensity {
        cloud.with_intensity((0..len).map(|i| value(3 * len + i)).collect())
    } else {
        Ok(cloud)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;

    /// A cloud of `n` points that no other test cloud repeats, with intensities when asked.
    fn cloud(seed: f32, n: usize, intensity: bool) -> PointCloud {
        let points = (0..n)
            .map(|i| {
                let t = seed + i as f32 * 0.37;
                Point3::new(t.sin() * 40.0, t.cos() * 0.001, -t * 1e-7)
            })
            .collect();
        let c = PointCloud::from_points(points);
        if intensity {
            c.with_intensity((0..n).map(|i| seed * i as f32).collect())
                .unwrap()
        } else {
            c
        }
    }

    /// A folder of this test's own under the system's temporary folder.
    fn folder(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("spot-nav-store-{name}-{}", std::process::id()))
    }

    /// Clouds written out come back bit for bit (positions and intensities, empty clouds too),
    /// the newest `resident` stay in memory, and the file goes with the store.
    #[test]
    fn clouds_written_out_come_back_bit_for_bit() {
        let dir = folder("round-trip");
        std::fs::create_dir_all(&dir).unwrap();
        let mut store = KeyframeClouds::in_folder(&dir, 3).unwrap();
        let clouds: Vec<PointCloud> = (0..10)
            .map(|k| cloud(k as f32, [500, 0, 37][k % 3], k % 2 == 0))
            .collect();
        for (k, c) in clouds.iter().enumerate() {
            store.push(c.clone()).unwrap();
            assert_eq!(store.held(), (k + 1).min(3));
        }
        assert_eq!(store.len(), 10);
        for (k, c) in clouds.iter().enumerate() {
            let back = store.get(k).unwrap().unwrap();
            assert_eq!(matches!(back, Cow::Borrowed(_)), k >= 7, "cloud {k}");
            let bits = |c: &PointCloud| -> Vec<u32> {
                c.points()
                    .iter()
                    .flat_map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                    .chain(c.intensity().into_iter().flatten().map(|v| v.to_bits()))
                    .collect()
            };
            assert_eq!(bits(&back), bits(c), "cloud {k}");
            assert_eq!(back.intensity().is_some(), c.intensity().is_some());
        }
        assert!(store.get(10).is_none());
        let files = || std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(files(), 1);
        drop(store);
        assert_eq!(files(), 0);
        // Without a file every cloud stays.
        let mut held = KeyframeClouds::default();
        for c in &clouds {
            held.push(c.clone()).unwrap();
        }
        assert_eq!(held.held(), 10);
        std::fs::remove_dir_all(dir).unwrap();
    }

    /// A folder that cannot hold the file is named in the error.
    #[test]
    fn a_store_in_a_missing_folder_is_refused_with_its_path() {
        let dir = folder("missing").join("no-such-folder");
        match KeyframeClouds::in_folder(&dir, 3) {
            Err(KeyframeCloudError::Store { path, action, .. }) => {
                assert!(path.starts_with(&dir));
                assert_eq!(action, "created");
            }
            Err(other) => panic!("expected a store error, got {other}"),
            Ok(_) => panic!("a store in a missing folder"),
        }
    }
}
