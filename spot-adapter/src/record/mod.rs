//! Recordings in: the spot-nav recording format ([`Recording`], written by
//! [`RecordingWriter`]) and KITTI-style sequence folders ([`KittiSequence`]), each a source of
//! [`Sample`](crate::robot::Sample)s read one scan at a time, interchangeable with a simulated
//! run for the engine.
//!
//! Uses `robot` (the sample type) and `slam-core`'s file formats only.

mod kitti;
mod recording;

pub use kitti::{KittiOdometry, KittiSamples, KittiSequence};
pub use recording::{Recording, RecordingSamples, RecordingWriter};
