//! The [`Uploader`] of the CUDA backend: places each grid of a scene where the [`VolumePolicy`]
//! decides, and owns that memory for the render.

use std::fmt;
use std::sync::{Arc, Mutex};

use cudarc::driver::{CudaContext, CudaStream, DevicePtr, DriverError};
use rayon::prelude::*;
use volpt_core::abi::{PlacedGrid, Uploader};
use volpt_core::{GridLayout, GridPlacement, TexelFormat};

use crate::error::GpuMemError;
use crate::layout::{brick_into, bricked, values_in};
use crate::memory::{HostRegistration, ManagedBuffer, PinnedBuffer};
use crate::policy::{decide, human_bytes, Placement, VolumeMemory, VolumePolicy};
use crate::texture::{texture_bytes, GridTexture};

/// Memory a render's scene is read from, kept only to be freed when the render ends.
type Held = Box<dyn Send>;

/// Where a grid went, for the log and the render's report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placed {
    pub bytes: u64,
    pub layout: GridLayout,
    pub memory: PlacedIn,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlacedIn {
    Device,
    /// Page-locked in place (the loader's own memory, no copy).
    ZeroCopyInPlace,
    /// Copied (or bricked) into page-locked memory.
    ZeroCopy,
    Managed {
        device_bytes: u64,
    },
    /// A 3D array read through a texture object, of texels of this format.
    Texture(TexelFormat),
}

impl fmt::Display for Placed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let layout = match self.layout {
            GridLayout::Dense => "dense",
            GridLayout::Bricked => "bricked",
            GridLayout::Sparse | GridLayout::SparseFlat => "sparse",
        };
        if let PlacedIn::Texture(texel) = self.memory {
            let texel = match texel {
                TexelFormat::F32 => "f32",
                TexelFormat::F16 => "f16",
            };
            return write!(
                f,
                "{} grid in a texture of {texel} texels",
                human_bytes(self.bytes)
            );
        }
        write!(f, "{} {layout} grid in ", human_bytes(self.bytes))?;
        match self.memory {
            PlacedIn::Device => write!(f, "device memory"),
            PlacedIn::ZeroCopyInPlace => write!(f, "host memory page-locked in place (zero-copy)"),
            PlacedIn::ZeroCopy => write!(f, "pinned host memory (zero-copy)"),
            PlacedIn::Managed { device_bytes } => write!(
                f,
                "managed memory, {} of it prefetched to the device",
                human_bytes(device_bytes)
            ),
            PlacedIn::Texture(_) => unreachable!("written above"),
        }
    }
}

/// Grids kept placed between renders of one scene: a viewer renders the same grids at every frame,
/// several GPUs at every batch, and copying them again each time cost more than rendering a frame.
/// Kept for one scene at a time: a render of another frees them ([`VolumePlacer::keeping`]).
#[derive(Default)]
pub struct ResidentGrids {
    kept: Mutex<Kept>,
}

#[derive(Default)]
struct Kept {
    /// The scene whose grids these are.
    scene: Option<u64>,
    grids: Vec<Resident>,
}

/// A grid kept on the device: what it was placed from, where it went, and its memory.
struct Resident {
    key: GridKey,
    placed: PlacedGrid,
    record: Placed,
    _memory: Held,
}

/// What a grid's placement depends on (the policy is the renderer's, the same for every render).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct GridKey {
    /// The host values' address and length.
    values: (usize, usize),
    res: [u32; 3],
    channels: u32,
    placement: GridPlacement,
    texel: TexelFormat,
}

impl ResidentGrids {
    pub fn new() -> Self {
        Self::default()
    }

    /// Bytes of grids kept now.
    pub fn bytes(&self) -> u64 {
        let kept = self.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.grids.iter().map(|r| r.record.bytes).sum()
    }
}

/// Places a scene's grids (and copies its other values, such as environment maps, to the device)
/// for one render; dropping it frees everything except the grids it keeps ([`Self::keeping`]).
pub struct VolumePlacer {
    ctx: Arc<CudaContext>,
    stream: Arc<CudaStream>,
    policy: VolumePolicy,
    free_device: u64,
    /// Device bytes taken by this render's grids so far.
    used: u64,
    held: Vec<Held>,
    placed: Vec<Placed>,
    error: Option<GpuMemError>,
    /// Where this render's grids are kept for the next render of the same scene, and the scene.
    keep: Option<(Arc<ResidentGrids>, u64)>,
}

impl VolumePlacer {
    /// A placer on `stream`'s device; asks the driver how much device memory is free now.
    ///
    /// # Safety
    /// Every slice given to [`Uploader::grid`] must stay live and unmoved until the placer is
    /// dropped: zero-copy grids are the caller's own memory, page-locked in place.
    pub unsafe fn new(stream: Arc<CudaStream>, policy: VolumePolicy) -> Result<Self, GpuMemError> {
        let ctx = stream.context().clone();
        let (free, total) = ctx.mem_get_info().map_err(|source| GpuMemError::Driver {
            doing: "asking how much device memory is free",
            bytes: 0,
            source,
        })?;
        tracing::debug!(
            free = %human_bytes(free as u64),
            total = %human_bytes(total as u64),
            budget = %human_bytes(policy.effective_budget(free as u64)),
            memory = %policy.memory,
            "placing volumes"
        );
        Ok(Self {
            ctx,
            stream,
            policy,
            free_device: free as u64,
            used: 0,
            held: Vec::new(),
            placed: Vec::new(),
            error: None,
            keep: None,
        })
    }

    /// This placer, taking the grids of scene `scene` from `resident` where an earlier render of
    /// it left them, and leaving the grids it places there for the next one. Grids that stay in
    /// the caller's memory (page-locked in place) are not kept: they must not outlive the render.
    /// A render of another scene frees the grids kept of the one before.
    ///
    /// # Safety
    /// `scene` names one scene's grids for as long as `resident` lives: every grid given to
    /// [`Uploader::grid`] under `scene`, by any placer keeping into `resident`, holds the same
    /// values whenever it is found at the same address with the same length (a scene whose grids
    /// are never written after loading, named by a number no other scene gets).
    pub unsafe fn keeping(mut self, resident: Arc<ResidentGrids>, scene: u64) -> Self {
        self.keep = Some((resident, scene));
        self
    }

    /// The grid of `key` as an earlier render of this scene left it; frees the grids of any other
    /// scene.
    fn kept(&mut self, key: &GridKey) -> Option<PlacedGrid> {
        let (resident, scene) = self.keep.as_ref()?;
        let mut kept = resident.kept.lock().unwrap_or_else(|e| e.into_inner());
        if kept.scene != Some(*scene) {
            // Another scene's grids: free them all, though the driver said otherwise when this
            // placer asked.
            self.free_device += free_kept(&self.stream, &mut kept.grids, |_| true);
            kept.scene = Some(*scene);
        }
        let Some(resident) = kept.grids.iter().find(|r| r.key == *key) else {
            // The same values placed otherwise before (another lookup or layout): this render
            // places them anew, and the scene's next render will find them so.
            self.free_device += free_kept(&self.stream, &mut kept.grids, |r| {
                r.key.values == key.values
            });
            return None;
        };
        let (placed, record) = (resident.placed, resident.record);
        drop(kept);
        tracing::debug!("volume kept from the render before: {record}");
        // Counted against the budget as if placed now; the driver's free memory, asked for when
        // this placer was made, already lacks it.
        self.used += on_device(&record);
        self.free_device += on_device(&record);
        self.placed.push(record);
        Some(placed)
    }

    /// Keeps the grid just placed for the next render of this scene, unless it stays in the
    /// caller's memory: its memory is the last held and its placement the last recorded (every
    /// placement holds one piece of memory and records itself once).
    fn keep(&mut self, key: GridKey, placed: PlacedGrid) {
        let Some((resident, _)) = &self.keep else {
            return;
        };
        let Some(&record) = self.placed.last() else {
            return;
        };
        if record.memory == PlacedIn::ZeroCopyInPlace {
            return;
        }
        let Some(memory) = self.held.pop() else {
            return;
        };
        let mut kept = resident.kept.lock().unwrap_or_else(|e| e.into_inner());
        kept.grids.push(Resident {
            key,
            placed,
            record,
            _memory: memory,
        });
    }

    /// The first error of any placement; the parameters built with this placer are only valid
    /// if this is `Ok`.
    pub fn check(&mut self) -> Result<(), GpuMemError> {
        self.error.take().map_or(Ok(()), Err)
    }

    /// Where each grid went, in the order the scene placed them.
    pub fn placed(&self) -> &[Placed] {
        &self.placed
    }

    fn place(
        &mut self,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        any_layout: bool,
    ) -> Result<PlacedGrid, GpuMemError> {
        let layout = match self.policy.layout {
            // The scene's kernels read this grid dense only (the factory selects the any-layout
            // medium when the description asks for bricks).
            GridLayout::Bricked if !any_layout => GridLayout::Dense,
            GridLayout::Bricked if values_in(GridLayout::Bricked, res, channels).is_none() => {
                tracing::warn!(
                    ?res,
                    "a grid padded to whole bricks would have 2^32 samples or more: it stays dense"
                );
                GridLayout::Dense
            }
            // Not a policy: a sparse grid arrives laid out (`Uploader::sparse`).
            GridLayout::Sparse | GridLayout::SparseFlat => GridLayout::Dense,
            layout => layout,
        };
        self.place_as(values, res, channels, layout)
    }

    /// [`VolumePlacer::place`] in `layout`: dense or flat sparse values as they are, or
    /// rewritten into bricks.
    fn place_as(
        &mut self,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        layout: GridLayout,
    ) -> Result<PlacedGrid, GpuMemError> {
        let len = match layout {
            GridLayout::Dense | GridLayout::Sparse | GridLayout::SparseFlat => values.len(),
            GridLayout::Bricked => values_in(layout, res, channels).unwrap_or(0) as usize,
        };
        let bytes = len as u64 * 4;
        let grid = Grid {
            values,
            res,
            channels,
            layout,
            len,
        };
        let (address, memory) = match decide(&self.policy, bytes, self.used, self.free_device) {
            Placement::OverBudget { left, budget } => {
                return Err(GpuMemError::OverBudget {
                    bytes,
                    left,
                    budget,
                })
            }
            Placement::Device => match self.copy_to_device(&grid) {
                Ok(address) => {
                    self.used += bytes;
                    (address, PlacedIn::Device)
                }
                Err(GpuMemError::OutOfDeviceMemory { .. })
                    if self.policy.memory == VolumeMemory::Auto =>
                {
                    tracing::warn!(
                        bytes = %human_bytes(bytes),
                        "the device has no room for the volume: reading it from host memory"
                    );
                    self.zero_copy(&grid)?
                }
                Err(e) => return Err(e),
            },
            Placement::ZeroCopy => self.zero_copy(&grid)?,
            Placement::Managed { device_bytes } => {
                let address = self.managed(&grid, device_bytes)?;
                self.used += device_bytes;
                (address, PlacedIn::Managed { device_bytes })
            }
        };
        self.record(Placed {
            bytes,
            layout,
            memory,
        });
        Ok(PlacedGrid {
            address,
            len: len as u64,
            layout,
            texture: 0,
        })
    }

    /// Logs where a grid went and keeps it for the render's report.
    fn record(&mut self, placed: Placed) {
        tracing::info!("volume: {placed}");
        self.placed.push(placed);
    }

    /// A texture of the grid: always in device memory (a texture cannot read the host's).
    fn texture(
        &mut self,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        texel: TexelFormat,
    ) -> Result<PlacedGrid, GpuMemError> {
        let bytes = texture_bytes(res, channels, texel);
        if let memory @ (VolumeMemory::ZeroCopy | VolumeMemory::Managed) = self.policy.memory {
            return Err(GpuMemError::TextureInHostMemory { memory });
        }
        let device = VolumePolicy {
            memory: VolumeMemory::Device,
            ..self.policy
        };
        if let Placement::OverBudget { left, budget } =
            decide(&device, bytes, self.used, self.free_device)
        {
            return Err(GpuMemError::TextureOverBudget {
                bytes,
                left,
                budget,
            });
        }
        let texture = GridTexture::new(&self.ctx, values, res, channels, texel)?;
        self.used += bytes;
        let address = texture.object();
        self.held.push(Box::new(texture));
        self.record(Placed {
            bytes,
            layout: GridLayout::Dense,
            memory: PlacedIn::Texture(texel),
        });
        Ok(PlacedGrid {
            address: 0,
            len: 0,
            layout: GridLayout::Dense,
            texture: address,
        })
    }

    fn copy_to_device(&mut self, grid: &Grid<'_>) -> Result<u64, GpuMemError> {
        let bytes = grid.len as u64 * 4;
        let copied = match grid.layout {
            GridLayout::Dense | GridLayout::Sparse | GridLayout::SparseFlat => {
                self.stream.clone_htod(grid.values)
            }
            GridLayout::Bricked => {
                let host = bricked(grid.values, grid.res, grid.channels)
                    .ok_or(GpuMemError::OutOfHostMemory { bytes })?;
                self.stream.clone_htod(&host)
            }
        };
        let slice = copied.map_err(|source| device_error(bytes, source))?;
        let (address, _) = slice.device_ptr(&self.stream);
        self.held.push(Box::new(slice));
        Ok(address)
    }

    fn zero_copy(&mut self, grid: &Grid<'_>) -> Result<(u64, PlacedIn), GpuMemError> {
        if grid.layout == GridLayout::Dense && owns_its_pages(grid.values) {
            match HostRegistration::new(&self.ctx, grid.values) {
                Ok(registration) => {
                    let address = registration.device_address();
                    // SAFETY: `new`'s contract: the values outlive the placer.
                    let registration = unsafe { registration.into_static() };
                    self.held.push(Box::new(registration));
                    return Ok((address, PlacedIn::ZeroCopyInPlace));
                }
                // Pages the caller registered already (only grids of `IN_PLACE_MIN_BYTES` or more
                // get here, which own their pages): copy the grid instead.
                Err(e) if HostRegistration::already_registered(&e) => {}
                Err(e @ GpuMemError::OutOfPinnedMemory { .. }) => return Err(e),
                // Registration is not supported everywhere (some virtualised or older systems):
                // pinned memory of our own still maps the grid, at the cost of a copy.
                Err(e) => tracing::warn!(%e, "cannot page-lock the volume in place: copying it"),
            }
        }
        let mut buffer = PinnedBuffer::zeroed(&self.ctx, grid.len)?;
        grid.write_into(buffer.as_mut_slice());
        let address = buffer.device_address();
        self.held.push(Box::new(buffer));
        Ok((address, PlacedIn::ZeroCopy))
    }

    fn managed(&mut self, grid: &Grid<'_>, device_bytes: u64) -> Result<u64, GpuMemError> {
        let mut buffer = ManagedBuffer::zeroed(&self.ctx, grid.len)?;
        grid.write_into(buffer.as_mut_slice());
        buffer.place(device_bytes, &self.stream)?;
        let address = buffer.device_address();
        self.held.push(Box::new(buffer));
        Ok(address)
    }
}

/// Frees the kept grids that `which` selects and returns the device bytes they took. The renders
/// that read them are over (each placer waits for its kernels before it is dropped); the stream is
/// waited for anyway rather than free memory a kernel could read.
/// The smallest grid page-locked in place: glibc serves every allocation this large (its largest
/// dynamic mmap threshold on 64-bit systems) from pages of its own.
const IN_PLACE_MIN_BYTES: usize = 32 << 20;

/// Whether registering `values` in place page-locks only pages that hold nothing else.
/// Registration covers whole pages ([`crate::memory::register_range`]); a small allocation shares
/// its first and last pages with its neighbours, and a CUDA copy whose host range then lies partly
/// in a registered range fails with `CUDA_ERROR_INVALID_VALUE` (the film read back after a render
/// of scenes/bucky, whose two grids are 128 and 384 KiB). A smaller grid is copied into pinned
/// memory of its own, which costs little at that size.
fn owns_its_pages(values: &[f32]) -> bool {
    std::mem::size_of_val(values) >= IN_PLACE_MIN_BYTES
}

fn free_kept(
    stream: &CudaStream,
    grids: &mut Vec<Resident>,
    which: impl Fn(&Resident) -> bool,
) -> u64 {
    if !grids.iter().any(&which) {
        return 0;
    }
    if let Err(e) = stream.synchronize() {
        tracing::error!(%e, "synchronising before freeing kept volumes");
    }
    let freed = grids
        .iter()
        .filter(|r| which(r))
        .map(|r| on_device(&r.record))
        .sum();
    grids.retain(|r| !which(r));
    tracing::debug!(bytes = freed, "freed kept volumes");
    freed
}

/// Device memory a placement takes.
fn on_device(placed: &Placed) -> u64 {
    match placed.memory {
        PlacedIn::Device | PlacedIn::Texture(_) => placed.bytes,
        PlacedIn::Managed { device_bytes } => device_bytes,
        PlacedIn::ZeroCopy | PlacedIn::ZeroCopyInPlace => 0,
    }
}

/// A grid being placed: its dense host values and the layout and length it takes on the device.
struct Grid<'v> {
    values: &'v [f32],
    res: [u32; 3],
    channels: u32,
    layout: GridLayout,
    len: usize,
}

impl Grid<'_> {
    /// Writes the grid in its layout into `out` (of `len` values).
    fn write_into(&self, out: &mut [f32]) {
        match self.layout {
            GridLayout::Dense | GridLayout::Sparse | GridLayout::SparseFlat => {
                const CHUNK: usize = 1 << 20;
                out.par_chunks_mut(CHUNK)
                    .zip(self.values.par_chunks(CHUNK))
                    .for_each(|(to, from)| to.copy_from_slice(from));
            }
            GridLayout::Bricked => brick_into(self.values, self.res, self.channels, out),
        }
    }
}

fn device_error(bytes: u64, source: DriverError) -> GpuMemError {
    if GpuMemError::is_out_of_memory(&source) {
        GpuMemError::OutOfDeviceMemory { bytes, source }
    } else {
        GpuMemError::Driver {
            doing: "copying a volume to the GPU",
            bytes,
            source,
        }
    }
}

impl Uploader for VolumePlacer {
    /// Environment maps and other values: always copied to device memory (they are small).
    fn values(&mut self, values: &[f32]) -> u64 {
        if self.error.is_some() {
            return 0;
        }
        match self.stream.clone_htod(values) {
            Ok(slice) => {
                let (address, _) = slice.device_ptr(&self.stream);
                self.held.push(Box::new(slice));
                address
            }
            Err(source) => {
                self.error = Some(device_error(values.len() as u64 * 4, source));
                0
            }
        }
    }

    fn grid(
        &mut self,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        placement: GridPlacement,
        texel: TexelFormat,
    ) -> PlacedGrid {
        let failed = PlacedGrid {
            address: 0,
            len: 0,
            layout: GridLayout::Dense,
            texture: 0,
        };
        let key = GridKey {
            values: (values.as_ptr() as usize, values.len()),
            res,
            channels,
            placement,
            texel,
        };
        self.place_once(key, failed, |placer| match placement {
            GridPlacement::Texture => placer.texture(values, res, channels, texel),
            GridPlacement::AnyLayout => placer.place(values, res, channels, true),
            GridPlacement::Dense => placer.place(values, res, channels, false),
        })
    }

    fn sparse(&mut self, data: &[f32], res: [u32; 3], channels: u32) -> PlacedGrid {
        let failed = PlacedGrid {
            address: 0,
            len: 0,
            layout: GridLayout::SparseFlat,
            texture: 0,
        };
        let key = GridKey {
            values: (data.as_ptr() as usize, data.len()),
            res,
            channels,
            placement: GridPlacement::AnyLayout,
            texel: TexelFormat::F32,
        };
        self.place_once(key, failed, |placer| {
            placer.place_sparse(data, res, channels)
        })
    }
}

impl VolumePlacer {
    /// The grid `key` names, placed by `place` once and kept; after an earlier failure, or when
    /// `place` fails (its error kept for the render to report), `failed`.
    fn place_once(
        &mut self,
        key: GridKey,
        failed: PlacedGrid,
        place: impl FnOnce(&mut Self) -> Result<PlacedGrid, GpuMemError>,
    ) -> PlacedGrid {
        if self.error.is_some() {
            return failed;
        }
        if let Some(placed) = self.kept(&key) {
            return placed;
        }
        match place(self) {
            Ok(placed) => {
                self.keep(key, placed);
                placed
            }
            Err(e) => {
                self.error = Some(e);
                failed
            }
        }
    }

    /// [`Uploader::sparse`]: the grid's flat copy ([`volpt_core::sparse::flatten`]), placed as
    /// the policy says as any other grid of its size (the kernels read no other sparse layout).
    fn place_sparse(
        &mut self,
        data: &[f32],
        res: [u32; 3],
        channels: u32,
    ) -> Result<PlacedGrid, GpuMemError> {
        let flat = volpt_core::sparse::flatten(data, res).ok_or_else(|| {
            GpuMemError::SparseTableTooLarge {
                bricks: volpt_core::sparse::bricks(res)
                    .iter()
                    .map(|&b| u64::from(b))
                    .product(),
                max: volpt_core::sparse::FLAT_MAX,
            }
        })?;
        self.place_as(&flat, res, channels, GridLayout::SparseFlat)
    }
}

impl Drop for VolumePlacer {
    fn drop(&mut self) {
        // Kernels may still read the memory after an error elsewhere: wait for them before
        // freeing it (a failed synchronisation leaves nothing better to do than to free).
        if let Err(e) = self.stream.synchronize() {
            tracing::error!(%e, "synchronising before freeing the volumes");
        }
        self.held.clear();
    }
}
