//! Safe owners of the CUDA driver's host-side memory kinds. Each checks every `CUresult`, frees
//! what it allocated exactly once (on drop, with its context current), and hands out the address
//! a kernel reads the values at.
//!
//! Drop never panics: a failure to free is logged (the process goes on; at worst it keeps the
//! memory).

use std::marker::PhantomData;
use std::ptr::NonNull;
use std::sync::Arc;

use cudarc::driver::{sys, CudaContext, CudaStream, DriverError};

use crate::error::GpuMemError;

/// `CU_DEVICE_CPU` of `cuda.h` (not in cudarc's bindings): the host, as a `cuMemAdvise` target.
const CU_DEVICE_CPU: sys::CUdevice = -1;

fn bytes_of(len: usize) -> u64 {
    len as u64 * std::mem::size_of::<f32>() as u64
}

/// Page-locked host memory mapped into the device's address space (`cuMemHostAlloc` with
/// `CU_MEMHOSTALLOC_DEVICEMAP`): the CPU writes it as a slice, kernels read it at
/// [`PinnedBuffer::device_address`] across the bus, without a copy.
pub struct PinnedBuffer {
    host: NonNull<f32>,
    len: usize,
    device: u64,
    ctx: Arc<CudaContext>,
}

// SAFETY: the buffer owns its memory exclusively, like a `Box<[f32]>`; the driver calls on it are
// thread-safe given a current context, which every method makes current first.
unsafe impl Send for PinnedBuffer {}
// SAFETY: shared access only reads.
unsafe impl Sync for PinnedBuffer {}

impl PinnedBuffer {
    /// `len` zeroed `f32`s of page-locked, device-mapped host memory in `ctx`.
    pub fn zeroed(ctx: &Arc<CudaContext>, len: usize) -> Result<Self, GpuMemError> {
        let bytes = bytes_of(len);
        let driver = |doing| {
            move |source| GpuMemError::Driver {
                doing,
                bytes,
                source,
            }
        };
        ctx.bind_to_thread()
            .map_err(driver("making the GPU's context current"))?;
        // A zero-byte request is an error for the driver: allocate one value at least.
        let size = len.max(1) * std::mem::size_of::<f32>();
        let mut host: *mut std::ffi::c_void = std::ptr::null_mut();
        let flags = sys::CU_MEMHOSTALLOC_DEVICEMAP | sys::CU_MEMHOSTALLOC_PORTABLE;
        // SAFETY: `host` is a valid out-pointer; the driver writes it only on success.
        unsafe { sys::cuMemHostAlloc(&mut host, size, flags) }
            .result()
            .map_err(|source| GpuMemError::OutOfPinnedMemory { bytes, source })?;
        let Some(host) = NonNull::new(host.cast::<f32>()) else {
            return Err(GpuMemError::Driver {
                doing: "allocating pinned host memory (the driver returned null)",
                bytes,
                source: DriverError(sys::CUresult::CUDA_ERROR_UNKNOWN),
            });
        };
        // From here on `Drop` frees the allocation, also on the error paths below.
        let mut buffer = Self {
            host,
            len,
            device: 0,
            ctx: ctx.clone(),
        };
        let mut device: sys::CUdeviceptr = 0;
        // SAFETY: `host` was returned by `cuMemHostAlloc` with DEVICEMAP in this context.
        unsafe { sys::cuMemHostGetDevicePointer_v2(&mut device, host.as_ptr().cast(), 0) }
            .result()
            .map_err(driver("mapping pinned host memory into the GPU"))?;
        buffer.device = device;
        // SAFETY: `size` bytes at `host` are ours; zero is a valid `f32`.
        unsafe { std::ptr::write_bytes(host.as_ptr().cast::<u8>(), 0, size) };
        Ok(buffer)
    }

    pub fn as_slice(&self) -> &[f32] {
        // SAFETY: `len` initialised (zeroed, then written as `f32`) values, owned by `self`.
        unsafe { std::slice::from_raw_parts(self.host.as_ptr(), self.len) }
    }

    pub fn as_mut_slice(&mut self) -> &mut [f32] {
        // SAFETY: as `as_slice`, and `&mut self` is exclusive.
        unsafe { std::slice::from_raw_parts_mut(self.host.as_ptr(), self.len) }
    }

    /// Where kernels read the values.
    pub fn device_address(&self) -> u64 {
        self.device
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl Drop for PinnedBuffer {
    fn drop(&mut self) {
        if let Err(e) = self.ctx.bind_to_thread() {
            tracing::error!(%e, "cannot make the GPU's context current to free pinned memory");
            return;
        }
        // SAFETY: allocated by `cuMemHostAlloc`, freed once, no slice of it outlives `self`.
        if let Err(e) = unsafe { sys::cuMemFreeHost(self.host.as_ptr().cast()) }.result() {
            tracing::error!(%e, bytes = bytes_of(self.len), "cuMemFreeHost failed");
        }
    }
}

/// The host's page size: registrations cover the whole pages that hold the values (page-locking
/// works on pages, and older drivers refuse unaligned ranges); a larger alignment could reach into
/// unmapped memory below an allocation.
pub fn page_size() -> usize {
    // SAFETY: sysconf only reads a system constant.
    let size = unsafe { libc::sysconf(libc::_SC_PAGESIZE) };
    usize::try_from(size)
        .ok()
        .filter(|s| s.is_power_of_two())
        .unwrap_or(4096)
}

/// The page-aligned range `(start, bytes)` that [`HostRegistration`] registers for `bytes` bytes
/// at `address`, with pages of `page` bytes (a power of two).
pub fn register_range(address: usize, bytes: usize, page: usize) -> (usize, usize) {
    let start = address & !(page - 1);
    let end = (address + bytes).next_multiple_of(page);
    (start, end - start)
}

/// A caller's host memory page-locked and mapped into the device in place (`cuMemHostRegister`
/// with `CU_MEMHOSTREGISTER_DEVICEMAP`): a loaded volume becomes readable by kernels without a
/// second copy. Unregistered on drop; the values must not move or be freed before that, which the
/// borrow `'a` guarantees.
pub struct HostRegistration<'a> {
    /// The start of the registered (aligned) range.
    base: NonNull<u8>,
    len: usize,
    device: u64,
    ctx: Arc<CudaContext>,
    _values: PhantomData<&'a [f32]>,
}

// SAFETY: it only refers to memory it borrows immutably for `'a`.
unsafe impl Send for HostRegistration<'_> {}
// SAFETY: as above.
unsafe impl Sync for HostRegistration<'_> {}

impl<'a> HostRegistration<'a> {
    /// Page-locks and maps `values` (the pages that hold them, [`register_range`]). Fails
    /// with `CUDA_ERROR_HOST_MEMORY_ALREADY_REGISTERED` when a page is registered already (small
    /// allocations can share one), which [`HostRegistration::already_registered`] recognises.
    pub fn new(ctx: &Arc<CudaContext>, values: &'a [f32]) -> Result<Self, GpuMemError> {
        let bytes = bytes_of(values.len());
        let driver = |doing| {
            move |source| GpuMemError::Driver {
                doing,
                bytes,
                source,
            }
        };
        if values.is_empty() {
            return Err(GpuMemError::Driver {
                doing: "page-locking an empty volume",
                bytes,
                source: DriverError(sys::CUresult::CUDA_ERROR_INVALID_VALUE),
            });
        }
        ctx.bind_to_thread()
            .map_err(driver("making the GPU's context current"))?;
        let address = values.as_ptr() as usize;
        let (start, size) = register_range(address, std::mem::size_of_val(values), page_size());
        let Some(base) = NonNull::new(start as *mut u8) else {
            return Err(driver("page-locking a volume at the first page of memory")(
                DriverError(sys::CUresult::CUDA_ERROR_INVALID_VALUE),
            ));
        };
        let flags = sys::CU_MEMHOSTREGISTER_DEVICEMAP | sys::CU_MEMHOSTREGISTER_PORTABLE;
        // SAFETY: the range is exactly the pages that hold `values` (mapped whole), live for
        // `'a`; registration only page-locks and maps them.
        unsafe { sys::cuMemHostRegister_v2(base.as_ptr().cast(), size, flags) }
            .result()
            .map_err(|source| match source.0 {
                sys::CUresult::CUDA_ERROR_OUT_OF_MEMORY => {
                    GpuMemError::OutOfPinnedMemory { bytes, source }
                }
                _ => driver("page-locking a volume in host memory")(source),
            })?;
        let mut registration = Self {
            base,
            len: values.len(),
            device: 0,
            ctx: ctx.clone(),
            _values: PhantomData,
        };
        let mut device: sys::CUdeviceptr = 0;
        // SAFETY: `base` is the start of a range registered with DEVICEMAP in this context.
        unsafe { sys::cuMemHostGetDevicePointer_v2(&mut device, base.as_ptr().cast(), 0) }
            .result()
            .map_err(driver("mapping a page-locked volume into the GPU"))?;
        registration.device = device + (address - start) as u64;
        Ok(registration)
    }

    /// Whether `error` (from [`HostRegistration::new`]) says the memory was registered already.
    pub fn already_registered(error: &GpuMemError) -> bool {
        matches!(
            error,
            GpuMemError::Driver { source, .. }
                if source.0 == sys::CUresult::CUDA_ERROR_HOST_MEMORY_ALREADY_REGISTERED
        )
    }

    /// Where kernels read the values.
    pub fn device_address(&self) -> u64 {
        self.device
    }

    /// The registration with its borrow forgotten.
    ///
    /// # Safety
    /// The registered values must stay live and unmoved until the result is dropped.
    pub unsafe fn into_static(self) -> HostRegistration<'static> {
        let this = std::mem::ManuallyDrop::new(self);
        HostRegistration {
            base: this.base,
            len: this.len,
            device: this.device,
            // SAFETY: read once from a value that is never dropped.
            ctx: unsafe { std::ptr::read(&this.ctx) },
            _values: PhantomData,
        }
    }
}

impl Drop for HostRegistration<'_> {
    fn drop(&mut self) {
        if let Err(e) = self.ctx.bind_to_thread() {
            tracing::error!(%e, "cannot make the GPU's context current to unregister a volume");
            return;
        }
        // SAFETY: registered by `new` at this address, unregistered once.
        if let Err(e) = unsafe { sys::cuMemHostUnregister(self.base.as_ptr().cast()) }.result() {
            tracing::error!(%e, bytes = bytes_of(self.len), "cuMemHostUnregister failed");
        }
    }
}

/// Managed memory (`cuMemAllocManaged`): one address for the CPU and the device; the driver
/// migrates or maps pages as the advice says ([`ManagedBuffer::place`]).
pub struct ManagedBuffer {
    address: sys::CUdeviceptr,
    len: usize,
    ctx: Arc<CudaContext>,
}

// SAFETY: owns its memory exclusively, like a `Box<[f32]>`.
unsafe impl Send for ManagedBuffer {}
// SAFETY: shared access only reads.
unsafe impl Sync for ManagedBuffer {}

impl ManagedBuffer {
    /// `len` zeroed `f32`s of managed memory, attached globally (any stream may read it).
    pub fn zeroed(ctx: &Arc<CudaContext>, len: usize) -> Result<Self, GpuMemError> {
        let bytes = bytes_of(len);
        ctx.bind_to_thread().map_err(|source| GpuMemError::Driver {
            doing: "making the GPU's context current",
            bytes,
            source,
        })?;
        let size = len.max(1) * std::mem::size_of::<f32>();
        let mut address: sys::CUdeviceptr = 0;
        // SAFETY: `address` is a valid out-pointer.
        unsafe {
            sys::cuMemAllocManaged(
                &mut address,
                size,
                sys::CUmemAttach_flags::CU_MEM_ATTACH_GLOBAL as u32,
            )
        }
        .result()
        .map_err(|source| GpuMemError::OutOfManagedMemory { bytes, source })?;
        let buffer = Self {
            address,
            len,
            ctx: ctx.clone(),
        };
        // SAFETY: `size` bytes of managed memory, host-accessible; no kernel runs on it yet.
        unsafe { std::ptr::write_bytes(address as *mut u8, 0, size) };
        Ok(buffer)
    }

    pub fn as_mut_slice(&mut self) -> &mut [f32] {
        // SAFETY: `len` initialised values, host-accessible, exclusive through `&mut self`; no
        // kernel reads them while the CPU holds this borrow (kernels run after `place`).
        unsafe { std::slice::from_raw_parts_mut(self.address as *mut f32, self.len) }
    }

    /// Where kernels (and the CPU) read the values.
    pub fn device_address(&self) -> u64 {
        self.address
    }

    /// Advises the driver where the values live: the first `device_bytes` (a multiple of
    /// [`crate::policy::MANAGED_GRANULE`], at most the buffer) preferred on the buffer's device and
    /// prefetched there on `stream`, the rest preferred in host memory and mapped for the device,
    /// so that the device reads it remotely instead of migrating (and evicting) pages.
    pub fn place(&self, device_bytes: u64, stream: &CudaStream) -> Result<(), GpuMemError> {
        let device = self.ctx.cu_device();
        let total = bytes_of(self.len);
        let device_bytes = device_bytes.min(total);
        let driver = |doing| {
            move |source| GpuMemError::Driver {
                doing,
                bytes: total,
                source,
            }
        };
        self.ctx
            .bind_to_thread()
            .map_err(driver("making the GPU's context current"))?;
        let advise = |offset: u64, count: u64, advice, target| {
            if count == 0 {
                return Ok(());
            }
            // SAFETY: `[offset, offset + count)` lies inside this allocation.
            unsafe {
                sys::cuMemAdvise(self.address + offset, count as usize, advice, target).result()
            }
        };
        use sys::CUmem_advise::{
            CU_MEM_ADVISE_SET_ACCESSED_BY, CU_MEM_ADVISE_SET_PREFERRED_LOCATION,
        };
        advise(
            0,
            device_bytes,
            CU_MEM_ADVISE_SET_PREFERRED_LOCATION,
            device,
        )
        .map_err(driver("advising managed memory to live on the GPU"))?;
        let rest = total - device_bytes;
        advise(
            device_bytes,
            rest,
            CU_MEM_ADVISE_SET_PREFERRED_LOCATION,
            CU_DEVICE_CPU,
        )
        .map_err(driver("advising managed memory to live in host memory"))?;
        advise(device_bytes, rest, CU_MEM_ADVISE_SET_ACCESSED_BY, device)
            .map_err(driver("mapping host-resident managed memory for the GPU"))?;
        if device_bytes > 0 {
            let stream = stream.cu_stream();
            // SAFETY: the range lies inside this allocation; `stream` is a live stream.
            unsafe { sys::cuMemPrefetchAsync(self.address, device_bytes as usize, device, stream) }
                .result()
                .map_err(driver("prefetching managed memory to the GPU"))?;
        }
        Ok(())
    }
}

impl Drop for ManagedBuffer {
    fn drop(&mut self) {
        if let Err(e) = self.ctx.bind_to_thread() {
            tracing::error!(%e, "cannot make the GPU's context current to free managed memory");
            return;
        }
        // SAFETY: allocated by `cuMemAllocManaged`, freed once, no slice of it outlives `self`.
        if let Err(e) = unsafe { sys::cuMemFree_v2(self.address) }.result() {
            tracing::error!(%e, bytes = bytes_of(self.len), "cuMemFree of managed memory failed");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registrations_cover_the_pages_that_hold_the_values() {
        let a = 4096;
        assert_eq!(register_range(a, a, a), (a, a));
        assert_eq!(register_range(a + 16, 8, a), (a, a));
        // A grid from malloc's mmap: 16 bytes into a page, 8 GiB long.
        let (start, size) = register_range(7 * a + 16, 8 << 30, a);
        assert_eq!((start, size), (7 * a, (8 << 30) + a));
        for page in [4096, 16384, 65536] {
            for (address, bytes) in [
                (1, 1),
                (page - 1, 2),
                (3 * page + 5, 10 * page),
                (12345, 678),
            ] {
                let (start, size) = register_range(address, bytes, page);
                assert_eq!(start % page, 0);
                assert_eq!(size % page, 0);
                assert!(start <= address && address + bytes <= start + size);
                // Never a page that holds no value.
                assert!(address - start < page && start + size - (address + bytes) < page);
            }
        }
        assert!(page_size().is_power_of_two() && page_size() >= 4096);
    }
}
