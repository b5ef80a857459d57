//! OpenVDB `.vdb` grids, read into volpt's sparse layout (or dense, where that is smaller).
//!
//! A VDB stores a volume as a tree whose leaves are 8^3 voxels, exactly volpt's bricks: each leaf
//! becomes one stored brick, each constant tile one stored brick shared by every brick it covers,
//! and every other brick of the box points at the background brick. The brick table has one entry
//! per 128^3 block of the box, plus one per brick of the blocks that are not uniform (those that
//! hold leaves or the edge of a tile, [`volpt_core::sparse`]): so a cloud in a mostly empty box
//! takes its leaves' memory plus at most 4 bytes per brick of the box, never the dense box, and a
//! tile of 4096^3 voxels loads in time and memory proportional to its blocks, not its bricks.
//!
//! The reader is volpt's own ([`format`], [`blosc`]): the one maintained-looking Rust reader,
//! `vdb-rs` 0.6 (January 2024), panics on unsupported maps and old versions, allocates whatever
//! sizes a file declares, hands blosc chunks to the C library unchecked and expands every leaf into
//! a tree of boxed nodes; none of which untrusted input may make volpt do (`limits`).
//!
//! Sample `(i, j, k)` of a VDB sits at `transform(i, j, k)`: voxel centres, so the grid is
//! cell-centred ([`GridConvention::Cell`]) over the box from half a voxel below the lowest stored
//! voxel to half a voxel above the highest, its edges on the stored bricks' edges.

mod blosc;
pub mod format;

use std::collections::HashMap;
use std::path::Path;

use crate::description::{Bounds, GridConvention, GridDesc, SampleLayout};
use crate::error::{GridProblem, SceneError};
use crate::limits;
use volpt_core::sparse::TablePlan;

use crate::sparse::{self, BRICK, BRICK_SAMPLES};

/// The grid a density is read from unless a scene names another (the name Blender, Houdini and
/// OpenVDB's own tools give a smoke density).
pub const DEFAULT_GRID: &str = "density";

/// When a VDB grid is kept sparse.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sparsity {
    /// Sparse when that takes at most half the dense grid's memory, or when the dense grid would
    /// exceed the memory limit.
    #[default]
    Auto,
    Always,
    Never,
}

impl Sparsity {
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Self::Auto),
            "always" | "true" => Some(Self::Always),
            "never" | "false" => Some(Self::Never),
            _ => None,
        }
    }
}

/// What to read from a `.vdb` file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VdbOptions {
    /// The grid's name; `None`: [`DEFAULT_GRID`], or the file's only float grid.
    pub grid: Option<String>,
    /// Whether the grid must be a vec3 grid (an albedo) instead of a float grid.
    pub vector: bool,
    pub sparsity: Sparsity,
}

fn problem(path: &Path, what: impl Into<String>, message: impl Into<String>) -> SceneError {
    SceneError::Grid {
        path: path.to_owned(),
        problem: GridProblem::Decode {
            what: what.into(),
            message: message.into(),
        },
    }
}

/// Whether `path` names a `.vdb` file (by its extension, as every format here is chosen).
pub fn is_vdb(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"))
}

/// The names and types of a `.vdb` file's grids (`volpt info`).
pub fn list_grids(path: &Path) -> Result<Vec<(String, String)>, SceneError> {
    let bytes = limits::read_file(path)?;
    let mut c = format::Cursor::new(&bytes);
    let header = format::header(&mut c).map_err(|e| problem(path, "the VDB header", e))?;
    Ok(header
        .grids
        .into_iter()
        .map(|d| (d.name, d.type_name + if d.half { " (half)" } else { "" }))
        .collect())
}

/// Reads one grid of a `.vdb` file.
pub fn read_vdb(path: &Path, options: &VdbOptions) -> Result<GridDesc, SceneError> {
    let bytes = limits::read_file(path)?;
    let mut c = format::Cursor::new(&bytes);
    let header = format::header(&mut c).map_err(|e| problem(path, "the VDB header", e))?;
    let descriptor = pick(path, &header.grids, options)?;
    let what = format!("grid {:?}", descriptor.name);
    if !descriptor.instance_of.is_empty() {
        return Err(SceneError::Grid {
            path: path.to_owned(),
            problem: GridProblem::Unsupported {
                what: format!("{what}, an instance of grid {:?}", descriptor.instance_of),
                reason: "instanced grids are not read; save the grid on its own".into(),
            },
        });
    }
    let topology = format::topology(&mut c, descriptor, header.version)
        .map_err(|e| problem(path, &what, e))?;
    let grid = sparse_grid(path, &what, &mut c, &topology)?;
    keep_or_densify(path, grid, options.sparsity)
}

/// The descriptor of the grid `options` ask for.
fn pick<'d>(
    path: &Path,
    grids: &'d [format::Descriptor],
    options: &VdbOptions,
) -> Result<&'d format::Descriptor, SceneError> {
    let channels = if options.vector { 3 } else { 1 };
    let fits = |d: &&format::Descriptor| format::channels_of(&d.type_name) == Some(channels);
    let found = match &options.grid {
        Some(name) => grids.iter().find(|d| &d.name == name),
        None => grids
            .iter()
            .find(|d| d.name == DEFAULT_GRID && fits(d))
            .or_else(|| {
                let mut candidates = grids.iter().filter(fits);
                match (candidates.next(), candidates.next()) {
                    (Some(only), None) => Some(only),
                    _ => None,
                }
            }),
    };
    let available = grids
        .iter()
        .map(|d| format!("{} ({})", d.name, d.type_name))
        .collect::<Vec<_>>()
        .join(", ");
    let kind = if options.vector { "vec3s" } else { "float" };
    let expected = match &options.grid {
        Some(name) => format!("a {kind} grid named {name:?}"),
        None => format!("a {kind} grid named {DEFAULT_GRID:?}, or a single {kind} grid"),
    };
    found
        .ok_or_else(|| SceneError::Grid {
            path: path.to_owned(),
            problem: GridProblem::BadField {
                line: None,
                field: "grid".into(),
                expected,
                found: if available.is_empty() {
                    "no grids".into()
                } else {
                    available.clone()
                },
            },
        })
        .and_then(|d| {
            if format::channels_of(&d.type_name) == Some(channels) {
                Ok(d)
            } else {
                Err(SceneError::Grid {
                    path: path.to_owned(),
                    problem: GridProblem::BadField {
                        line: None,
                        field: format!("grid {:?}", d.name),
                        expected: format!("a {kind} grid"),
                        found: d.type_name.clone(),
                    },
                })
            }
        })
}

/// The stored box of a topology in index space, `[min, max)` per axis, on brick edges.
fn index_box(t: &format::Topology) -> Option<([i64; 3], [i64; 3])> {
    let nodes = t
        .leaves
        .iter()
        .map(|o| (*o, BRICK))
        .chain(t.tiles.iter().map(|tile| (tile.origin, tile.dim)));
    nodes.fold(None, |acc, (o, dim)| {
        let lo = o.map(i64::from);
        let hi = lo.map(|v| v + i64::from(dim));
        Some(match acc {
            None => (lo, hi),
            Some((a, b)) => (
                [0, 1, 2].map(|i| a[i].min(lo[i])),
                [0, 1, 2].map(|i| b[i].max(hi[i])),
            ),
        })
    })
}

/// The grid in the sparse layout: sizes checked against the memory limit before anything of the
/// grid's size is allocated, then tiles and leaves written into their bricks.
fn sparse_grid(
    path: &Path,
    what: &str,
    c: &mut format::Cursor<'_>,
    t: &format::Topology,
) -> Result<GridDesc, SceneError> {
    let ch = t.channels;
    let Some((lo, hi)) = index_box(t) else {
        return Err(problem(
            path,
            what,
            "the grid stores no voxels (every value is the background)",
        ));
    };
    let res64 = [0, 1, 2].map(|i| hi[i] - lo[i]);
    if res64.iter().any(|&r| r > i64::from(u32::MAX - BRICK)) {
        return Err(SceneError::Grid {
            path: path.to_owned(),
            problem: GridProblem::TooLarge {
                resolution: res64.map(|r| r.min(i64::from(u32::MAX)) as u32),
                channels: ch as u32,
                limit: u64::from(u32::MAX),
            },
        });
    }
    let res = res64.map(|r| r as u32);
    // One stored brick per distinct tile value, shared by every brick its tile covers.
    let mut tile_slots: HashMap<Vec<u32>, u32> = HashMap::new();
    for tile in &t.tiles {
        let key = tile.value.iter().map(|v| v.to_bits()).collect();
        let next = 1 + tile_slots.len() as u32;
        tile_slots.entry(key).or_insert(next);
    }
    let slots = 1 + tile_slots.len() as u64 + t.leaves.len() as u64;
    if slots << 9 > u64::from(u32::MAX) {
        return Err(problem(
            path,
            what,
            format!("{slots} bricks: at most 2^23 bricks can be stored"),
        ));
    }
    let first_leaf = 1 + tile_slots.len();
    // The regions of the box each node covers, in bricks, tiles first and leaves over them (as
    // the tree reads: a node's children over its tiles), each with its stored brick.
    let brick_of =
        |o: [i32; 3]| [0, 1, 2].map(|i| ((i64::from(o[i]) - lo[i]) / i64::from(BRICK)) as u32);
    let regions = || {
        let tiles = t.tiles.iter().map(|tile| {
            let key: Vec<u32> = tile.value.iter().map(|v| v.to_bits()).collect();
            let from = brick_of(tile.origin);
            (from, from.map(|b| b + tile.dim / BRICK), tile_slots[&key])
        });
        let leaves = t.leaves.iter().enumerate().map(|(i, &origin)| {
            let from = brick_of(origin);
            (from, from.map(|b| b + 1), (first_leaf + i) as u32)
        });
        tiles.chain(leaves)
    };
    // The brick table in two passes (`volpt_core::sparse::TablePlan`): which 128^3 blocks are
    // uniform (4 bytes per block of the box, checked first), then the mixed blocks' entries.
    let box_size = format!("a box of {} x {} x {} voxels", res[0], res[1], res[2]);
    let coarse = sparse::coarse_values(res);
    limits::check_memory(
        path,
        &format!("{what}: the brick table's blocks for {box_size}"),
        coarse.and_then(|v| limits::bytes_of(v, 4)),
    )?;
    if coarse.is_none_or(|c| c > u64::from(u32::MAX)) {
        return Err(problem(
            path,
            what,
            format!("{box_size} has more than 2^32 blocks of 128^3 voxels"),
        ));
    }
    let mut plan = TablePlan::new(res);
    for (from, to, slot) in regions() {
        plan.paint(from, to, slot);
    }
    let fine = plan.fine_len();
    let values = slots
        .checked_mul((BRICK_SAMPLES * ch) as u64)
        .and_then(|v| v.checked_add(fine)?.checked_add(coarse?));
    limits::check_memory(
        path,
        &format!(
            "{what}: {slots} bricks of {ch} channels and a brick table of {} entries for \
             {box_size}",
            fine + coarse.unwrap_or(0)
        ),
        values.and_then(|v| limits::bytes_of(v, 4)),
    )?;
    if fine >= u64::from(volpt_core::sparse::UNIFORM) {
        return Err(problem(
            path,
            what,
            format!("{fine} brick table entries: at most 2^31 - 1"),
        ));
    }
    let brick = BRICK_SAMPLES * ch;
    let stored = slots as usize * brick;
    let mut data = Vec::with_capacity(values.unwrap_or(0) as usize);
    data.resize(stored, 0.0);
    for (i, v) in data[..brick].iter_mut().enumerate() {
        *v = t.background[i % ch];
    }
    for (value, &slot) in &tile_slots {
        let at = slot as usize * brick;
        for (i, v) in data[at..at + brick].iter_mut().enumerate() {
            *v = f32::from_bits(value[i % ch]);
        }
    }
    format::leaf_buffers(c, t, |i, leaf| {
        let at = (first_leaf + i) * brick;
        // OpenVDB's leaf order is z fastest; a brick's is x fastest.
        for x in 0..BRICK {
            for y in 0..BRICK {
                for z in 0..BRICK {
                    let from = (((x * BRICK + y) * BRICK + z) as usize) * ch;
                    let to = at + sparse::inner(x, y, z) * ch;
                    data[to..to + ch].copy_from_slice(&leaf[from..from + ch]);
                }
            }
        }
    })
    .map_err(|e| problem(path, what, e))?;
    let mut table = plan.into_table();
    for (from, to, slot) in regions() {
        table.paint(from, to, slot);
    }
    table.append_to(&mut data);
    let world = |i: usize, index: i64| {
        (t.transform.translation[i] + t.transform.scale[i] * (index as f64 - 0.5)) as f32
    };
    let bounds = Bounds {
        min: [0, 1, 2].map(|i| world(i, lo[i])),
        max: [0, 1, 2].map(|i| world(i, hi[i])),
    };
    if (0..3).any(|i| !(bounds.min[i].is_finite() && bounds.max[i] > bounds.min[i])) {
        return Err(problem(
            path,
            what,
            format!(
                "the grid's world box {:?} .. {:?} is empty or not finite in f32",
                bounds.min, bounds.max
            ),
        ));
    }
    Ok(GridDesc {
        resolution: res,
        channels: ch as u32,
        bounds,
        convention: GridConvention::Cell,
        data,
        layout: SampleLayout::Sparse,
    })
}

/// The sparse grid, or its dense copy where `sparsity` asks for it.
fn keep_or_densify(
    path: &Path,
    grid: GridDesc,
    sparsity: Sparsity,
) -> Result<GridDesc, SceneError> {
    let dense = grid.dense_bytes();
    let fits = dense.is_some_and(|d| d <= limits::memory_limit());
    let dense_wanted = match sparsity {
        Sparsity::Always => false,
        Sparsity::Never => true,
        Sparsity::Auto => fits && dense.is_some_and(|d| grid.stored_bytes() * 2 > d),
    };
    if !dense_wanted {
        return Ok(grid);
    }
    let [x, y, z] = grid.resolution;
    limits::check_grid_memory(
        path,
        [x, y, z],
        grid.channels,
        dense.unwrap_or(u64::MAX) / 4,
    )?;
    Ok(grid.densified())
}
