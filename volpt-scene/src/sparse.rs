//! Sparse grids ([`SampleLayout::Sparse`]): the stored 8^3 bricks of a volume and a table that
//! says which brick of the box each one is, in `volpt_core::GridLayout::Sparse`'s layout, so that
//! the renderer reads the description's `data` as it is. An empty brick costs one table entry (4
//! bytes) instead of 512 samples, and the background brick (slot 0) is stored once.
//!
//! Everything that reads a grid's values reads [`GridDesc::samples`]: the stored samples without
//! the table, whose entries are slot numbers in `f32` bits, not values.

use crate::description::{GridDesc, SampleLayout};

/// Samples along each edge of a brick (`volpt_core::grid::BRICK`).
pub const BRICK: u32 = 8;
/// Samples in a brick.
pub const BRICK_SAMPLES: usize = (BRICK * BRICK * BRICK) as usize;

/// Bricks along each axis of a grid of `res` samples.
pub fn bricks(res: [u32; 3]) -> [u32; 3] {
    res.map(|r| r.div_ceil(BRICK))
}

/// Entries of the brick table of a grid of `res` samples, or `None` if that overflows.
pub fn table_len(res: [u32; 3]) -> Option<u64> {
    bricks(res)
        .iter()
        .try_fold(1u64, |acc, &b| acc.checked_mul(u64::from(b)))
}

/// Where sample `(x, y, z)` sits inside its brick (x fastest), before the channel count.
pub fn inner(x: u32, y: u32, z: u32) -> usize {
    let m = BRICK - 1;
    (((z & m) * BRICK + (y & m)) * BRICK + (x & m)) as usize
}

impl GridDesc {
    /// The stored samples: all of `data` for a dense grid, the bricks without the table for a
    /// sparse one.
    pub fn samples(&self) -> &[f32] {
        &self.data[..self.samples_len()]
    }

    /// [`GridDesc::samples`], to change values in place (the table stays as it is).
    pub fn samples_mut(&mut self) -> &mut [f32] {
        let n = self.samples_len();
        &mut self.data[..n]
    }

    fn samples_len(&self) -> usize {
        match self.layout {
            SampleLayout::Dense => self.data.len(),
            SampleLayout::Sparse => {
                let table = table_len(self.resolution).unwrap_or(0) as usize;
                self.data.len().saturating_sub(table)
            }
        }
    }

    /// A sparse grid's brick table: the stored slot of every brick of the box, x fastest.
    pub fn brick_table(&self) -> impl Iterator<Item = u32> + '_ {
        let samples = match self.layout {
            SampleLayout::Dense => self.data.len(),
            SampleLayout::Sparse => self.samples_len(),
        };
        self.data[samples..].iter().map(|v| v.to_bits())
    }

    /// Bytes the grid's `data` takes.
    pub fn stored_bytes(&self) -> u64 {
        self.data.len() as u64 * 4
    }

    /// Bytes a dense copy of the grid would take (`None`: more than `u64` holds).
    pub fn dense_bytes(&self) -> Option<u64> {
        self.resolution
            .iter()
            .try_fold(u64::from(self.channels) * 4, |acc, &r| {
                acc.checked_mul(u64::from(r))
            })
    }

    /// The sample `(x, y, z)` (inside the grid), channel `c`.
    pub fn sample(&self, x: u32, y: u32, z: u32, c: u32) -> f32 {
        let ch = self.channels as usize;
        let [rx, ry, _] = self.resolution;
        let i = match self.layout {
            SampleLayout::Dense => {
                ((z as usize * ry as usize + y as usize) * rx as usize + x as usize) * ch
            }
            SampleLayout::Sparse => {
                let [bx, by, _] = bricks(self.resolution);
                let brick = ((z / BRICK) as usize * by as usize + (y / BRICK) as usize)
                    * bx as usize
                    + (x / BRICK) as usize;
                let slot = self.data[self.samples_len() + brick].to_bits() as usize;
                (slot * BRICK_SAMPLES + inner(x, y, z)) * ch
            }
        };
        self.data[i + c as usize]
    }

    /// The same grid, dense. The caller checks the dense size against the memory limit first.
    pub fn densified(&self) -> GridDesc {
        if self.layout == SampleLayout::Dense {
            return self.clone();
        }
        let [rx, ry, rz] = self.resolution;
        let mut data = Vec::with_capacity(self.dense_bytes().unwrap_or(0) as usize / 4);
        for z in 0..rz {
            for y in 0..ry {
                for x in 0..rx {
                    for c in 0..self.channels {
                        data.push(self.sample(x, y, z, c));
                    }
                }
            }
        }
        GridDesc {
            data,
            layout: SampleLayout::Dense,
            ..self.clone_header()
        }
    }

    /// The grid's fields without its data.
    pub fn clone_header(&self) -> GridDesc {
        GridDesc {
            resolution: self.resolution,
            channels: self.channels,
            bounds: self.bounds,
            convention: self.convention,
            data: Vec::new(),
            layout: self.layout,
        }
    }
}

/// Checks a sparse grid's shape: whole bricks (at least the background brick) then a table whose
/// every entry names a stored brick, and fewer than 2^32 stored samples (the lookup's index is
/// `u32`). `Err` says what is wrong.
pub fn check(grid: &GridDesc) -> Result<(), String> {
    let table = table_len(grid.resolution).ok_or("the brick table overflows")? as usize;
    let brick = BRICK_SAMPLES * grid.channels as usize;
    let Some(stored) = grid.data.len().checked_sub(table) else {
        return Err(format!(
            "{} values cannot hold a brick table of {table} entries",
            grid.data.len()
        ));
    };
    if brick == 0 || stored < brick || stored % brick != 0 {
        return Err(format!(
            "{stored} stored values are not whole bricks of {brick} values (at least one)"
        ));
    }
    let slots = stored / brick;
    if (slots as u64) << 9 > u64::from(u32::MAX) {
        return Err(format!("{slots} bricks: at most 2^23 bricks can be stored"));
    }
    if let Some((i, slot)) = grid
        .brick_table()
        .enumerate()
        .find(|&(_, s)| s as usize >= slots)
    {
        return Err(format!(
            "brick table entry {i} names brick {slot}, but {slots} are stored"
        ));
    }
    Ok(())
}
