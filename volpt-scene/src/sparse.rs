//! Sparse grids ([`SampleLayout::Sparse`]): the stored 8^3 bricks of a volume and a two-level
//! table that says which stored brick each brick of the box reads, in
//! `volpt_core::GridLayout::Sparse`'s layout ([`volpt_core::sparse`]), so that the renderer reads
//! the description's `data` as it is. An empty brick costs at most one table entry (4 bytes)
//! instead of 512 samples, a uniform 128^3 block (empty, or inside a tile) one entry in all, and
//! the background brick (slot 0) is stored once.
//!
//! Everything that reads a grid's values reads [`GridDesc::samples`]: the stored samples without
//! the table, whose entries are slot numbers in `f32` bits, not values.

use volpt_core::sparse::{self as table, BrickTable};

use crate::description::{GridDesc, SampleLayout};

/// Samples along each edge of a brick (`volpt_core::grid::BRICK`).
pub const BRICK: u32 = 8;
/// Samples in a brick.
pub const BRICK_SAMPLES: usize = (BRICK * BRICK * BRICK) as usize;

/// Bricks along each axis of a grid of `res` samples.
pub fn bricks(res: [u32; 3]) -> [u32; 3] {
    table::bricks(res)
}

/// Bricks of the box of a grid of `res` samples, or `None` if that overflows.
pub fn box_bricks(res: [u32; 3]) -> Option<u64> {
    bricks(res)
        .iter()
        .try_fold(1u64, |acc, &b| acc.checked_mul(u64::from(b)))
}

/// Values a sparse grid of `res` samples takes besides its stored bricks and fine entries: the
/// coarse table and the fine entries' count (`None`: more than `u64` holds).
pub fn coarse_values(res: [u32; 3]) -> Option<u64> {
    table::coarse_len(res).and_then(|c| c.checked_add(1))
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
            SampleLayout::Sparse => table::stored_values(&self.data, self.resolution),
        }
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
                let brick = [x, y, z].map(|v| v / BRICK);
                let slot = table::slot(&self.data, self.resolution, brick) as usize;
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

/// Checks a sparse grid's shape: whole bricks (at least the background brick), then a brick
/// table whose every entry names a stored brick or its own fine entries, and fewer than 2^32
/// stored samples (the lookup's index is `u32`). `Err` says what is wrong.
pub fn check(grid: &GridDesc) -> Result<(), String> {
    table::parts(&grid.data, grid.resolution, grid.channels)
        .map(|_| ())
        .map_err(|e| e.to_string())
}

impl GridDesc {
    /// The same grid in the sparse layout: bricks whose samples are all zero point at one zero
    /// brick (slot 0), the others are stored; where no brick is all zero, slot 0 is the first
    /// brick. Samples past the edge of the grid (padding, never read) repeat the edge, so that
    /// the stored samples hold only the grid's own values. A sparse grid is returned as it is.
    pub fn sparsified(&self) -> GridDesc {
        if self.layout == SampleLayout::Sparse {
            return self.clone();
        }
        let ch = self.channels as usize;
        let [rx, ry, rz] = self.resolution;
        let [bx, by, bz] = bricks(self.resolution);
        let size = BRICK_SAMPLES * ch;
        let mut bricks_data: Vec<Vec<f32>> = Vec::new();
        let mut slots = Vec::with_capacity((bx * by * bz) as usize);
        let mut zero_slot = None;
        for kz in 0..bz {
            for ky in 0..by {
                for kx in 0..bx {
                    let mut brick = vec![0.0; size];
                    for z in 0..BRICK {
                        for y in 0..BRICK {
                            for x in 0..BRICK {
                                let at = |o: u32, v: u32, r: u32| (o * BRICK + v).min(r - 1);
                                let (sx, sy, sz) = (at(kx, x, rx), at(ky, y, ry), at(kz, z, rz));
                                for c in 0..ch {
                                    brick[inner(x, y, z) * ch + c] =
                                        self.sample(sx, sy, sz, c as u32);
                                }
                            }
                        }
                    }
                    let slot = if brick.iter().all(|&v| v == 0.0) {
                        *zero_slot.get_or_insert_with(|| {
                            bricks_data.push(brick);
                            bricks_data.len() - 1
                        })
                    } else {
                        bricks_data.push(brick);
                        bricks_data.len() - 1
                    };
                    slots.push(slot as u32);
                }
            }
        }
        // Slot 0 is the brick empty regions point at: the zero brick, if there is one.
        if let Some(zero) = zero_slot.filter(|&z| z != 0) {
            bricks_data.swap(0, zero);
            for slot in &mut slots {
                *slot = match *slot as usize {
                    s if s == zero => 0,
                    0 => zero as u32,
                    s => s as u32,
                };
            }
        }
        let mut data: Vec<f32> = bricks_data.into_iter().flatten().collect();
        BrickTable::from_slots(self.resolution, &slots).append_to(&mut data);
        GridDesc {
            data,
            layout: SampleLayout::Sparse,
            ..self.clone_header()
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::description::{Bounds, GridConvention, GridDesc, SampleLayout};

    fn grid(res: [u32; 3], channels: u32, f: impl Fn(u32, u32, u32, u32) -> f32) -> GridDesc {
        let mut data = Vec::new();
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    for c in 0..channels {
                        data.push(f(x, y, z, c));
                    }
                }
            }
        }
        GridDesc {
            resolution: res,
            channels,
            bounds: Bounds {
                min: [0.0; 3],
                max: [1.0; 3],
            },
            convention: GridConvention::Cell,
            data,
            layout: SampleLayout::Dense,
        }
    }

    #[test]
    fn sparsified_grids_hold_the_same_samples_and_densify_back() {
        for (res, channels) in [([20, 9, 17], 1), ([8, 8, 8], 3), ([30, 3, 9], 3)] {
            // Zero except a slab: most bricks are empty.
            let dense = grid(res, channels, |x, y, z, c| {
                if (9..14).contains(&x) {
                    (x + 2 * y + 3 * z + c) as f32 * 0.5
                } else {
                    0.0
                }
            });
            let sparse = dense.sparsified();
            super::check(&sparse).unwrap();
            assert_eq!(sparse.densified(), dense, "{res:?}");
            assert!(sparse.samples().len() < sparse.data.len());
        }
        let uniform = grid([9, 9, 9], 1, |_, _, _, _| 2.5);
        let sparse = uniform.sparsified();
        assert!(
            sparse.samples().iter().all(|&v| v == 2.5),
            "padding repeats the edge"
        );
        assert_eq!(sparse.densified(), uniform);
    }
}
