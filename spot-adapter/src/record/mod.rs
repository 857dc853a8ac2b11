//! Recordings in: the spot-nav recording format ([`Recording`], written by
//! [`RecordingWriter`]) and KITTI-style sequence folders ([`KittiSequence`]), each a source of
//! [`Sample`](crate::robot::Sample)s read one scan at a time, interchangeable with a simulated
//! run for the engine.
//!
//! Every file is read only when it is a regular file of at most [`MAX_RECORDING_FILE_BYTES`].
//!
//! Uses `robot` (the sample type) and `slam-core`'s file formats only.

mod bounded_file;
mod kitti;
mod recording;

pub use bounded_file::MAX_RECORDING_FILE_BYTES;
pub use kitti::{KittiOdometry, KittiSamples, KittiSequence};
pub use recording::{
    IndexEntry, Recording, RecordingSamples, RecordingWriter, calibration_text, parse_calibration,
    parse_index,
};
