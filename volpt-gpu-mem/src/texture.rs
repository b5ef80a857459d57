//! Grids in 3D CUDA arrays read through texture objects, filtered by the texture unit
//! (`volpt_core::TextureTrilinear`; the thesis read its grids this way).
//!
//! A texture object made with clamp addressing, linear filtering and unnormalised coordinates
//! reads texel `i` at coordinate `i + 0.5` and repeats the edge texels beyond the outermost ones,
//! which is `volpt_core::Grid`'s reconstruction. Arrays hold 1, 2 or 4 channels: an RGB grid
//! takes four, the fourth zero.

use std::ptr;
use std::sync::Arc;

use cudarc::driver::sys;
use cudarc::driver::{CudaContext, DriverError};
use half::f16;
use volpt_core::TexelFormat;

use crate::error::GpuMemError;

/// A texture object and the array it reads; dropping it destroys both.
pub struct GridTexture {
    ctx: Arc<CudaContext>,
    array: sys::CUarray,
    object: sys::CUtexObject,
}

// SAFETY: the handles are plain driver handles, valid in any thread that binds `ctx`.
unsafe impl Send for GridTexture {}

/// Channels an array of `channels`-channel samples takes (1, 2 or 4).
fn array_channels(channels: u32) -> u32 {
    match channels {
        1 | 2 => channels,
        _ => 4,
    }
}

/// Bytes a texture of `res` samples of `channels` channels of `texel`s takes on the device.
pub fn texture_bytes(res: [u32; 3], channels: u32, texel: TexelFormat) -> u64 {
    let texel_bytes = match texel {
        TexelFormat::F32 => 4,
        TexelFormat::F16 => 2,
    };
    res.iter().map(|&r| u64::from(r)).product::<u64>()
        * u64::from(array_channels(channels))
        * texel_bytes
}

impl GridTexture {
    /// A texture of the dense grid `values` (`res` samples of `channels` channels, x fastest),
    /// each sample as `texel` holds it ([`TexelFormat::texel`]).
    pub fn new(
        ctx: &Arc<CudaContext>,
        values: &[f32],
        res: [u32; 3],
        channels: u32,
        texel: TexelFormat,
    ) -> Result<Self, GpuMemError> {
        let bytes = texture_bytes(res, channels, texel);
        let driver = |doing: &'static str| {
            move |source: DriverError| {
                if GpuMemError::is_out_of_memory(&source) {
                    GpuMemError::TextureOutOfMemory { bytes, source }
                } else {
                    GpuMemError::Driver {
                        doing,
                        bytes,
                        source,
                    }
                }
            }
        };
        ctx.bind_to_thread()
            .map_err(driver("binding the context for a texture"))?;
        let wide = array_channels(channels) as usize;
        let c = channels as usize;
        let texels = values.len() / c;
        let padded = |i: usize, k: usize| {
            if k < c {
                texel.texel(values[i * c + k])
            } else {
                0.0
            }
        };
        // The host copy in the array's format; the samples are already `texel`s, so the
        // conversion to half is exact.
        let host: Vec<u8> = match texel {
            TexelFormat::F32 => (0..texels * wide)
                .flat_map(|j| padded(j / wide, j % wide).to_ne_bytes())
                .collect(),
            TexelFormat::F16 => (0..texels * wide)
                .flat_map(|j| f16::from_f32(padded(j / wide, j % wide)).to_ne_bytes())
                .collect(),
        };
        let format = match texel {
            TexelFormat::F32 => sys::CUarray_format::CU_AD_FORMAT_FLOAT,
            TexelFormat::F16 => sys::CUarray_format::CU_AD_FORMAT_HALF,
        };
        let descriptor = sys::CUDA_ARRAY3D_DESCRIPTOR {
            Width: res[0] as usize,
            Height: res[1] as usize,
            Depth: res[2] as usize,
            Format: format,
            NumChannels: wide as u32,
            Flags: 0,
        };
        let mut array = ptr::null_mut();
        // SAFETY: a valid descriptor and an out pointer.
        unsafe { sys::cuArray3DCreate_v2(&mut array, &descriptor) }
            .result()
            .map_err(driver("allocating a 3D array for a grid texture"))?;
        let mut texture = Self {
            ctx: ctx.clone(),
            array,
            object: 0,
        };
        let row_bytes = res[0] as usize * (host.len() / texels);
        // Every field written: `mem::zeroed` is invalid here (the memory types have no 0).
        let copy = sys::CUDA_MEMCPY3D {
            srcXInBytes: 0,
            srcY: 0,
            srcZ: 0,
            srcLOD: 0,
            srcMemoryType: sys::CUmemorytype::CU_MEMORYTYPE_HOST,
            srcHost: host.as_ptr().cast(),
            srcDevice: 0,
            srcArray: ptr::null_mut(),
            reserved0: ptr::null_mut(),
            srcPitch: row_bytes,
            srcHeight: res[1] as usize,
            dstXInBytes: 0,
            dstY: 0,
            dstZ: 0,
            dstLOD: 0,
            dstMemoryType: sys::CUmemorytype::CU_MEMORYTYPE_ARRAY,
            dstHost: ptr::null_mut(),
            dstDevice: 0,
            dstArray: array,
            reserved1: ptr::null_mut(),
            dstPitch: 0,
            dstHeight: 0,
            WidthInBytes: row_bytes,
            Height: res[1] as usize,
            Depth: res[2] as usize,
        };
        // SAFETY: the source holds `Depth` planes of `Height` rows of `WidthInBytes` bytes, the
        // array's extent; the copy is synchronous.
        unsafe { sys::cuMemcpy3D_v2(&copy) }
            .result()
            .map_err(driver("copying a grid into its texture"))?;
        // SAFETY: zeroed is valid for these C structs (their enums' first values are 0): the
        // resource is an array (0), unused fields zero.
        let mut resource: sys::CUDA_RESOURCE_DESC = unsafe { std::mem::zeroed() };
        resource.resType = sys::CUresourcetype::CU_RESOURCE_TYPE_ARRAY;
        resource.res.array.hArray = array;
        // SAFETY: as above.
        let mut description: sys::CUDA_TEXTURE_DESC = unsafe { std::mem::zeroed() };
        description.addressMode = [sys::CUaddress_mode::CU_TR_ADDRESS_MODE_CLAMP; 3];
        description.filterMode = sys::CUfilter_mode::CU_TR_FILTER_MODE_LINEAR;
        // Unnormalised coordinates (the flag not set); no trilinear shortcuts, so that the
        // filter is the documented one the CPU reproduces.
        description.flags = sys::CU_TRSF_DISABLE_TRILINEAR_OPTIMIZATION;
        // SAFETY: valid descriptions of a live array; an out pointer.
        unsafe {
            sys::cuTexObjectCreate(&mut texture.object, &resource, &description, ptr::null())
        }
        .result()
        .map_err(driver("creating a grid's texture object"))?;
        Ok(texture)
    }

    /// The texture object, as kernels receive it.
    pub fn object(&self) -> u64 {
        self.object
    }
}

impl Drop for GridTexture {
    fn drop(&mut self) {
        if self.ctx.bind_to_thread().is_err() {
            return;
        }
        // SAFETY: handles this value created and nothing else destroys.
        unsafe {
            if self.object != 0 {
                let _ = sys::cuTexObjectDestroy(self.object);
            }
            let _ = sys::cuArrayDestroy(self.array);
        }
    }
}
