//! Spot's local grids (`GetLocalGrids`: terrain height, obstacle distance, no-step, ...)
//! decoded into metric cell values, and into spot-nav's [`BitGrid`].

use slam_core::{BitGrid, GridError, GridGeometry};

use crate::grpc::GridProblem;
use crate::grpc::api;
use crate::grpc::api::local_grid_service_client::LocalGridServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::session::{Session, check_header};

/// The directory name of Spot's local grid service.
const LOCAL_GRID_SERVICE: &str = "local-grid-service";

impl Session {
    /// The grids named `names`, in that order.
    pub(crate) async fn local_grids(&self, names: &[&str]) -> Result<Vec<LocalGrid>, SpotError> {
        let mut client = LocalGridServiceClient::new(self.service(LOCAL_GRID_SERVICE)?);
        let request = api::GetLocalGridsRequest {
            header: Some(self.header()),
            local_grid_requests: names
                .iter()
                .map(|&n| api::LocalGridRequest {
                    local_grid_type_name: n.to_owned(),
                })
                .collect(),
        };
        let response = self
            .rpc("GetLocalGrids", client.get_local_grids(request))
            .await?;
        check_header("GetLocalGrids", response.header.as_ref())?;
        names
            .iter()
            .map(|&name| {
                let reply = response
                    .local_grid_responses
                    .iter()
                    .find(|r| r.local_grid_type_name == name)
                    .ok_or_else(|| SpotError::MalformedGrid {
                        grid: name.to_owned(),
                        problem: GridProblem::Missing,
                    })?;
                if reply.status != api::local_grid_response::Status::Ok as i32 {
                    return Err(SpotError::NoData {
                        what: name.to_owned(),
                        status: api::local_grid_response::Status::try_from(reply.status)
                            .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name()),
                    });
                }
                let grid = reply
                    .local_grid
                    .as_ref()
                    .ok_or_else(|| SpotError::MalformedGrid {
                        grid: name.to_owned(),
                        problem: GridProblem::OkWithoutGrid,
                    })?;
                decode_grid(grid)
            })
            .collect()
    }
}

/// One local grid: `num_cells_x` by `num_cells_y` cells of `cell_size` metres in the frame
/// `frame_name`, whose origin is the outer corner of cell (0, 0); values already scaled
/// (`raw * cell_value_scale + cell_value_offset`). Cells are stored with x fastest.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalGrid {
    /// The grid type (`terrain`, `obstacle_distance`, `no_step`, ...).
    pub type_name: String,
    /// The frame the grid lies in (its snapshot gives the frame's pose).
    pub frame_name: String,
    /// Cell side, metres.
    pub cell_size: f64,
    /// Cells along x.
    pub num_cells_x: u32,
    /// Cells along y.
    pub num_cells_y: u32,
    /// Scaled cell values, index `x + y * num_cells_x`.
    pub values: Vec<f64>,
}

impl LocalGrid {
    /// The value of cell (x, y), or `None` off the grid.
    #[must_use]
    pub fn value(&self, x: u32, y: u32) -> Option<f64> {
        (x < self.num_cells_x && y < self.num_cells_y)
            .then(|| self.values[x as usize + y as usize * self.num_cells_x as usize])
    }

    /// A [`BitGrid`] of the same cells, blocked where `blocked(value)`, placed with its cell
    /// (0, 0) corner at the origin of [`LocalGrid::frame_name`] and `cell_size` resolution.
    ///
    /// # Errors
    /// As [`BitGrid::new`] and [`GridGeometry::try_new`].
    pub fn to_bit_grid(&self, mut blocked: impl FnMut(f64) -> bool) -> Result<BitGrid, GridError> {
        let geometry = GridGeometry::try_new(nalgebra::Vector2::zeros(), self.cell_size)?;
        let grid = BitGrid::from_fn(self.num_cells_x, self.num_cells_y, |x, y| {
            self.value(x, y).is_some_and(&mut blocked)
        })?;
        Ok(grid.with_geometry(geometry))
    }
}

/// Decode one grid: extent, cell format (all six), RAW or RLE encoding, scale and offset.
///
/// # Errors
/// [`SpotError::MalformedGrid`] for a bad extent, an unknown format or encoding, RLE counts that
/// do not sum to the cell count, or data of the wrong size.
pub(crate) fn decode_grid(grid: &api::LocalGrid) -> Result<LocalGrid, SpotError> {
    let bad = |problem: GridProblem| SpotError::MalformedGrid {
        grid: grid.local_grid_type_name.clone(),
        problem,
    };
    let extent = grid
        .extent
        .as_ref()
        .ok_or_else(|| bad(GridProblem::NoExtent))?;
    let (nx, ny) = (extent.num_cells_x, extent.num_cells_y);
    let (Ok(num_cells_x), Ok(num_cells_y)) = (u32::try_from(nx), u32::try_from(ny)) else {
        return Err(bad(GridProblem::NegativeSide { x: nx, y: ny }));
    };
    if !(extent.cell_size.is_finite() && extent.cell_size > 0.0) {
        return Err(bad(GridProblem::CellSize(extent.cell_size)));
    }
    let cells = (num_cells_x as usize)
        .checked_mul(num_cells_y as usize)
        .filter(|&n| n as u64 <= slam_core::MAX_GRID_CELLS)
        .ok_or_else(|| bad(GridProblem::TooLarge { x: nx, y: ny }))?;
    let format = api::local_grid::CellFormat::try_from(grid.cell_format)
        .map_err(|_| bad(GridProblem::UnknownFormat(grid.cell_format)))?;
    let width = cell_bytes(format).ok_or_else(|| bad(GridProblem::UnknownFormat(0)))?;
    if !grid.data.len().is_multiple_of(width) {
        return Err(bad(GridProblem::PartialCell {
            bytes: grid.data.len(),
            cell_bytes: width,
        }));
    }
    let stored: Vec<f64> = grid
        .data
        .chunks_exact(width)
        .map(|c| cell_value(format, c))
        .collect();
    let raw = match api::local_grid::Encoding::try_from(grid.encoding) {
        Ok(api::local_grid::Encoding::Raw) => {
            if stored.len() != cells {
                return Err(bad(GridProblem::RawSize {
                    stored: stored.len(),
                    cells,
                }));
            }
            stored
        }
        Ok(api::local_grid::Encoding::Rle) => {
            run_length_decode(&stored, &grid.rle_counts, cells).map_err(bad)?
        }
        _ => {
            return Err(bad(GridProblem::Encoding(grid.encoding)));
        }
    };
    // A scale of 0 is the message's default: the values are then stored unscaled.
    let scale = if grid.cell_value_scale == 0.0 {
        1.0
    } else {
        grid.cell_value_scale
    };
    let offset = grid.cell_value_offset;
    if !(scale.is_finite() && offset.is_finite()) {
        return Err(bad(GridProblem::NonFiniteScale));
    }
    Ok(LocalGrid {
        type_name: grid.local_grid_type_name.clone(),
        frame_name: grid.frame_name_local_grid_data.clone(),
        cell_size: extent.cell_size,
        num_cells_x,
        num_cells_y,
        values: raw.into_iter().map(|v| v * scale + offset).collect(),
    })
}

/// Bytes per cell of a format, `None` for the unknown format.
fn cell_bytes(format: api::local_grid::CellFormat) -> Option<usize> {
    use api::local_grid::CellFormat as F;
    match format {
        F::Unknown => None,
        F::Int8 | F::Uint8 => Some(1),
        F::Int16 | F::Uint16 => Some(2),
        F::Float32 => Some(4),
        F::Float64 => Some(8),
    }
}

/// One little-endian cell as a number (`chunk` has the format's width).
fn cell_value(format: api::local_grid::CellFormat, c: &[u8]) -> f64 {
    use api::local_grid::CellFormat as F;
    match format {
        F::Int8 => f64::from(i8::from_le_bytes([c[0]])),
        F::Uint8 => f64::from(c[0]),
        F::Int16 => f64::from(i16::from_le_bytes([c[0], c[1]])),
        F::Uint16 => f64::from(u16::from_le_bytes([c[0], c[1]])),
        F::Float32 => f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])),
        F::Float64 => f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]),
        F::Unknown => f64::NAN,
    }
}

/// RLE: `values[k]` repeated `counts[k]` times, which must make exactly `cells` cells.
fn run_length_decode(
    values: &[f64],
    counts: &[i32],
    cells: usize,
) -> Result<Vec<f64>, GridProblem> {
    if values.len() != counts.len() {
        return Err(GridProblem::RunLengths {
            values: values.len(),
            counts: counts.len(),
        });
    }
    let mut out = Vec::with_capacity(cells);
    for (k, (&value, &count)) in values.iter().zip(counts).enumerate() {
        let count = usize::try_from(count).map_err(|_| GridProblem::NegativeRun(k))?;
        if out.len() + count > cells {
            return Err(GridProblem::RunsTooLong(cells));
        }
        out.extend(std::iter::repeat_n(value, count));
    }
    if out.len() != cells {
        return Err(GridProblem::RunsTooShort {
            held: out.len(),
            cells,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(
        format: api::local_grid::CellFormat,
        encoding: api::local_grid::Encoding,
    ) -> api::LocalGrid {
        api::LocalGrid {
            local_grid_type_name: "terrain".into(),
            frame_name_local_grid_data: "odom".into(),
            extent: Some(api::LocalGridExtent {
                cell_size: 0.1,
                num_cells_x: 3,
                num_cells_y: 2,
            }),
            cell_format: format as i32,
            encoding: encoding as i32,
            ..Default::default()
        }
    }

    #[test]
    fn raw_int16_cells_are_scaled_and_offset() {
        let mut g = grid(
            api::local_grid::CellFormat::Int16,
            api::local_grid::Encoding::Raw,
        );
        g.data = [-2i16, -1, 0, 1, 2, 300]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        g.cell_value_scale = 0.5;
        g.cell_value_offset = 1.0;
        let decoded = decode_grid(&g).unwrap();
        assert_eq!(decoded.values, vec![0.0, 0.5, 1.0, 1.5, 2.0, 151.0]);
        assert_eq!(decoded.value(2, 1), Some(151.0));
        assert_eq!(decoded.value(3, 0), None);
        let bits = decoded.to_bit_grid(|v| v > 1.2).unwrap();
        assert_eq!(bits.count_blocked(), 3);
        assert!((bits.geometry().resolution - 0.1).abs() < 1e-12);
    }

    #[test]
    fn rle_runs_expand_and_must_cover_the_grid_exactly() {
        let mut g = grid(
            api::local_grid::CellFormat::Uint8,
            api::local_grid::Encoding::Rle,
        );
        g.data = vec![7, 0, 9];
        g.rle_counts = vec![2, 3, 1];
        assert_eq!(
            decode_grid(&g).unwrap().values,
            vec![7.0, 7.0, 0.0, 0.0, 0.0, 9.0]
        );
        g.rle_counts = vec![2, 3, 2];
        assert!(matches!(
            decode_grid(&g),
            Err(SpotError::MalformedGrid { .. })
        ));
        g.rle_counts = vec![2, 3];
        assert!(decode_grid(&g).is_err());
    }

    #[test]
    fn a_raw_grid_of_the_wrong_size_or_format_is_an_error() {
        let mut g = grid(
            api::local_grid::CellFormat::Float32,
            api::local_grid::Encoding::Raw,
        );
        g.data = vec![0; 4 * 5];
        assert!(decode_grid(&g).is_err());
        g.data = vec![0; 4 * 6 + 1];
        assert!(decode_grid(&g).is_err());
        g.data = vec![0; 4 * 6];
        assert!(decode_grid(&g).is_ok());
        g.cell_format = 42;
        assert!(decode_grid(&g).is_err());
        g.cell_format = api::local_grid::CellFormat::Float32 as i32;
        g.extent = Some(api::LocalGridExtent {
            cell_size: 0.1,
            num_cells_x: -3,
            num_cells_y: 2,
        });
        assert!(decode_grid(&g).is_err());
    }
}
