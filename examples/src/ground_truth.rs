//! A ground-truth trajectory given on the command line (`slam --ground-truth FILE`): a TUM file
//! (`stamp tx ty tz qx qy qz qw` a line) or KITTI poses (12 numbers a line, a row-major `[R|t]`,
//! one line per scan in the recording's order, stamped with the scans' own stamps), told apart
//! by the count of numbers on the first pose line. Either holds `world_T_body` poses.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use slam_core::Pose3;
use slam_core::io::{StampedPose, parse_kitti_poses, parse_tum};

/// The two formats a ground-truth file may be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroundTruthFormat {
    /// TUM: `stamp tx ty tz qx qy qz qw`, 8 numbers a line.
    Tum,
    /// KITTI poses: 12 numbers a line, one line per scan.
    Kitti,
}

/// The poses of a ground-truth file.
#[derive(Clone, Debug)]
enum Poses {
    Stamped(Vec<StampedPose>),
    PerScan(Vec<Pose3>),
}

/// A ground-truth file, read and checked.
#[derive(Clone, Debug)]
pub struct GroundTruthFile {
    path: PathBuf,
    poses: Poses,
}

/// Lines that hold data (not blank, not a `#` comment), with their 1-based numbers.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(k, line)| (k + 1, line.trim()))
        .filter(|(_, line)| !line.is_empty() && !line.starts_with('#'))
}

impl GroundTruthFile {
    /// Reads `path`: TUM when its first pose line has 8 numbers, KITTI poses when it has 12.
    ///
    /// # Errors
    /// The file cannot be read, holds no pose, its first line is neither format, a line is
    /// malformed (the error names the file and the line), or TUM stamps do not increase.
    pub fn read(path: &Path) -> Result<Self> {
        let context = || format!("reading the ground truth {}", path.display());
        let text = std::fs::read_to_string(path).with_context(context)?;
        let Some((first_line, first)) = data_lines(&text).next() else {
            bail!("{}: no pose (an empty file)", path.display());
        };
        let poses = match first.split_whitespace().count() {
            8 => {
                let poses = parse_tum(&text).with_context(context)?;
                // Association by stamp needs stamps that increase.
                let lines = data_lines(&text).map(|(n, _)| n).skip(1);
                for (w, n) in poses.windows(2).zip(lines) {
                    if w[1].stamp <= w[0].stamp {
                        bail!(
                            "{}: line {n}: stamp {} is not after the one before ({})",
                            path.display(),
                            w[1].stamp,
                            w[0].stamp
                        );
                    }
                }
                Poses::Stamped(poses)
            }
            12 => Poses::PerScan(parse_kitti_poses(&text).with_context(context)?),
            n => bail!(
                "{}: line {first_line}: {n} numbers; a ground truth is a TUM file (8 numbers a line: stamp tx ty tz qx qy qz qw) or KITTI poses (12 a line)",
                path.display()
            ),
        };
        Ok(Self {
            path: path.to_path_buf(),
            poses,
        })
    }

    /// The file's format.
    #[must_use]
    pub fn format(&self) -> GroundTruthFormat {
        match self.poses {
            Poses::Stamped(_) => GroundTruthFormat::Tum,
            Poses::PerScan(_) => GroundTruthFormat::Kitti,
        }
    }

    /// How many poses it holds.
    #[must_use]
    pub fn len(&self) -> usize {
        match &self.poses {
            Poses::Stamped(p) => p.len(),
            Poses::PerScan(p) => p.len(),
        }
    }

    /// Always false: a file without a pose is refused when read.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The file, its format and its count, e.g. `gt.txt (KITTI poses, 300 poses)`.
    #[must_use]
    pub fn describe(&self) -> String {
        let format = match self.format() {
            GroundTruthFormat::Tum => "TUM",
            GroundTruthFormat::Kitti => "KITTI poses, one a scan",
        };
        format!("{} ({format}, {} poses)", self.path.display(), self.len())
    }

    /// KITTI poses must be one a scan: checked against the recording's count of scans before
    /// the run (TUM files are matched by stamp and need no count).
    ///
    /// # Errors
    /// KITTI poses whose count is not `scans`.
    pub fn check_count(&self, scans: usize) -> Result<()> {
        match &self.poses {
            Poses::PerScan(p) if p.len() != scans => bail!(
                "{}: {} KITTI poses for {scans} scans (KITTI poses are one a scan, in the recording's order)",
                self.path.display(),
                p.len()
            ),
            _ => Ok(()),
        }
    }

    /// The poses with their stamps: a TUM file's own, or for KITTI poses the stamps of the
    /// scans read (`stamps`, in the recording's order).
    ///
    /// # Errors
    /// KITTI poses whose count is not that of `stamps`.
    pub fn stamped(&self, stamps: &[f64]) -> Result<Vec<StampedPose>> {
        match &self.poses {
            Poses::Stamped(p) => Ok(p.clone()),
            Poses::PerScan(p) => {
                self.check_count(stamps.len())?;
                Ok(p.iter()
                    .zip(stamps)
                    .map(|(&pose, &stamp)| StampedPose { stamp, pose })
                    .collect())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    // Stamps and coordinates read back from text must be the numbers written.
    #![allow(clippy::float_cmp)]

    use super::*;

    fn written(name: &str, text: &str) -> PathBuf {
        let path = std::env::temp_dir().join(format!("spot-nav-gt-{}-{name}", std::process::id()));
        std::fs::write(&path, text).unwrap();
        path
    }

    #[test]
    fn tum_and_kitti_told_apart_by_content() {
        let tum = written(
            "a.txt",
            "# stamp x y z qx qy qz qw\n1.0 0 0 0 0 0 0 1\n1.1 1 0 0 0 0 0 1\n",
        );
        let t = GroundTruthFile::read(&tum).unwrap();
        assert_eq!((t.format(), t.len()), (GroundTruthFormat::Tum, 2));
        assert_eq!(t.stamped(&[]).unwrap()[1].stamp, 1.1);
        let kitti = written(
            "b.tum",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 2 0 1 0 0 0 0 1 0\n",
        );
        let k = GroundTruthFile::read(&kitti).unwrap();
        assert_eq!((k.format(), k.len()), (GroundTruthFormat::Kitti, 2));
        let s = k.stamped(&[5.0, 5.1]).unwrap();
        assert_eq!((s[1].stamp, s[1].pose.translation.x), (5.1, 2.0));
        let e = format!("{:#}", k.stamped(&[5.0]).unwrap_err());
        assert!(
            e.contains("2 KITTI poses for 1 scans") && e.contains("b.tum"),
            "{e}"
        );
        for file in [tum, kitti] {
            let _ = std::fs::remove_file(file);
        }
    }

    #[test]
    fn bad_files_name_the_file_and_line() {
        let cases = [
            ("c.tum", "", "no pose"),
            ("d.tum", "1 2 3 4 5\n", "line 1: 5 numbers"),
            (
                "e.tum",
                "# x\n1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 1\n",
                "line 3",
            ),
            (
                "f.tum",
                "1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n",
                "line 2: stamp",
            ),
            ("g.tum", "1.0 0 0 0 0 0 0 1\n1.1 0 0 0 0 0 0 5\n", "line 2"),
            (
                "h.txt",
                "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0\n",
                "line 2",
            ),
        ];
        for (name, text, expect) in cases {
            let file = written(name, text);
            let e = format!("{:#}", GroundTruthFile::read(&file).unwrap_err());
            let _ = std::fs::remove_file(&file);
            assert!(e.contains(name) && e.contains(expect), "{name}: {e}");
        }
        let missing = std::env::temp_dir().join("spot-nav-no-such-ground-truth.tum");
        let e = format!("{:#}", GroundTruthFile::read(&missing).unwrap_err());
        assert!(e.contains("spot-nav-no-such-ground-truth.tum"), "{e}");
    }
}
