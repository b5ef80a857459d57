//! Where a render's grids go: the choice of `--volume-memory` and `--device-memory-budget`, made
//! per grid from sizes alone, so that it is the same decision on every machine and testable
//! without a GPU.

use volpt_core::GridLayout;

/// Where the kernels read a volume from (`--volume-memory`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VolumeMemory {
    /// Copied to device memory (fastest; the volume must fit).
    #[default]
    Device,
    /// Page-locked host memory mapped into the device's address space: every lookup crosses PCIe
    /// (or NVLink-C2C), nothing is copied ahead.
    ZeroCopy,
    /// Managed memory: the part that fits the budget is prefetched to the device and preferred
    /// there, the rest stays in host memory and is read remotely like zero-copy memory.
    Managed,
    /// On the device while the volumes fit the budget, zero-copy beyond it (and when a device
    /// allocation fails).
    Auto,
}

impl VolumeMemory {
    pub const ALL: [VolumeMemory; 4] = [
        VolumeMemory::Device,
        VolumeMemory::ZeroCopy,
        VolumeMemory::Managed,
        VolumeMemory::Auto,
    ];

    /// The name `--volume-memory` takes.
    pub fn name(self) -> &'static str {
        match self {
            VolumeMemory::Device => "device",
            VolumeMemory::ZeroCopy => "zerocopy",
            VolumeMemory::Managed => "managed",
            VolumeMemory::Auto => "auto",
        }
    }
}

impl std::str::FromStr for VolumeMemory {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|m| m.name()).collect();
                format!("expected one of {}, found {s:?}", names.join(", "))
            })
    }
}

impl std::fmt::Display for VolumeMemory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// How one render places its grids.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VolumePolicy {
    pub memory: VolumeMemory,
    /// The layout of grids on the device (the host's grids are dense).
    pub layout: GridLayout,
    /// The most bytes of device memory the render's grids may take (`--device-memory-budget`);
    /// `None`: what the device has free, less [`DEVICE_RESERVE`].
    pub budget: Option<u64>,
}

/// Device memory left free for everything but the grids (film, counters, the kernels' stacks and
/// the driver's own allocations), when the budget is what the device has free.
pub const DEVICE_RESERVE: u64 = 512 << 20;

/// Managed memory is advised and prefetched in whole units of this size: the driver migrates
/// managed memory in pages of up to 2 MiB, and a unit that straddled the device-preferred part and
/// the host-preferred part would be advised twice.
pub const MANAGED_GRANULE: u64 = 2 << 20;

/// Where one grid goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    Device,
    ZeroCopy,
    /// Managed memory, of which the first `device_bytes` are preferred on and prefetched to the
    /// device, the rest preferred in host memory and mapped for the device.
    Managed {
        device_bytes: u64,
    },
    /// `--volume-memory device` and the grid does not fit the budget.
    OverBudget {
        left: u64,
        budget: u64,
    },
}

impl VolumePolicy {
    /// The device bytes the render's grids may take: the budget, never more than what the device
    /// has free less [`DEVICE_RESERVE`] (`free_device`: `cuMemGetInfo`'s free bytes).
    pub fn effective_budget(&self, free_device: u64) -> u64 {
        let free = free_device.saturating_sub(DEVICE_RESERVE);
        self.budget.map_or(free, |b| b.min(free))
    }
}

/// Where a grid of `bytes` goes, when this render's grids already take `used` bytes of device
/// memory and the device has `free_device` bytes free.
pub fn decide(policy: &VolumePolicy, bytes: u64, used: u64, free_device: u64) -> Placement {
    let budget = policy.effective_budget(free_device);
    let left = budget.saturating_sub(used);
    match policy.memory {
        VolumeMemory::Device if policy.budget.is_some() && bytes > left => Placement::OverBudget {
            left,
            budget: policy.budget.unwrap_or(budget),
        },
        // Without a budget, the allocation itself says whether it fits.
        VolumeMemory::Device => Placement::Device,
        VolumeMemory::ZeroCopy => Placement::ZeroCopy,
        VolumeMemory::Auto if bytes <= left => Placement::Device,
        VolumeMemory::Auto => Placement::ZeroCopy,
        VolumeMemory::Managed => Placement::Managed {
            device_bytes: bytes.min(left / MANAGED_GRANULE * MANAGED_GRANULE),
        },
    }
}

/// Bytes for people: `1.50 GiB`, `12.0 MiB`, `512 B`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    match unit {
        0 => format!("{bytes} B"),
        _ if value < 10.0 => format!("{value:.2} {}", UNITS[unit]),
        _ => format!("{value:.1} {}", UNITS[unit]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GIB: u64 = 1 << 30;

    fn policy(memory: VolumeMemory, budget: Option<u64>) -> VolumePolicy {
        VolumePolicy {
            memory,
            layout: GridLayout::Dense,
            budget,
        }
    }

    #[test]
    fn auto_keeps_what_fits_the_budget_on_the_device_and_maps_the_rest() {
        let auto = policy(VolumeMemory::Auto, Some(2 * GIB));
        let free = 80 * GIB;
        assert_eq!(decide(&auto, GIB, 0, free), Placement::Device);
        assert_eq!(decide(&auto, 2 * GIB, 0, free), Placement::Device);
        assert_eq!(decide(&auto, 2 * GIB + 1, 0, free), Placement::ZeroCopy);
        assert_eq!(decide(&auto, 8 * GIB, 0, free), Placement::ZeroCopy);
        // The second grid of the render (an albedo after the density) sees what the first took.
        assert_eq!(decide(&auto, GIB, GIB + 1, free), Placement::ZeroCopy);
        assert_eq!(decide(&auto, GIB, GIB, free), Placement::Device);
    }

    #[test]
    fn the_budget_never_exceeds_what_the_device_has_free() {
        let auto = policy(VolumeMemory::Auto, Some(64 * GIB));
        let free = 4 * GIB;
        assert_eq!(auto.effective_budget(free), free - DEVICE_RESERVE);
        assert_eq!(decide(&auto, 3 * GIB, 0, free), Placement::Device);
        assert_eq!(decide(&auto, 4 * GIB, 0, free), Placement::ZeroCopy);
        // Without a budget, auto uses what is free.
        let unbounded = policy(VolumeMemory::Auto, None);
        assert_eq!(decide(&unbounded, 3 * GIB, 0, free), Placement::Device);
        assert_eq!(decide(&unbounded, 4 * GIB, 0, free), Placement::ZeroCopy);
        // A device with less free than the reserve keeps nothing.
        assert_eq!(unbounded.effective_budget(DEVICE_RESERVE / 2), 0);
        assert_eq!(decide(&unbounded, 4, 0, 0), Placement::ZeroCopy);
    }

    #[test]
    fn device_refuses_a_grid_over_an_explicit_budget_only() {
        let device = policy(VolumeMemory::Device, Some(2 * GIB));
        assert_eq!(decide(&device, 2 * GIB, 0, 80 * GIB), Placement::Device);
        assert_eq!(
            decide(&device, 3 * GIB, 0, 80 * GIB),
            Placement::OverBudget {
                left: 2 * GIB,
                budget: 2 * GIB
            }
        );
        // No budget: the allocation decides (and fails with a clear error if it must).
        let device = policy(VolumeMemory::Device, None);
        assert_eq!(decide(&device, 100 * GIB, 0, 80 * GIB), Placement::Device);
    }

    #[test]
    fn zerocopy_ignores_the_budget() {
        let zerocopy = policy(VolumeMemory::ZeroCopy, Some(0));
        assert_eq!(decide(&zerocopy, 1, 0, 80 * GIB), Placement::ZeroCopy);
        assert_eq!(decide(&zerocopy, 100 * GIB, 0, 0), Placement::ZeroCopy);
    }

    #[test]
    fn managed_prefers_on_the_device_only_whole_granules_within_the_budget() {
        let managed = policy(VolumeMemory::Managed, Some(2 * GIB));
        let free = 80 * GIB;
        assert_eq!(
            decide(&managed, GIB, 0, free),
            Placement::Managed { device_bytes: GIB }
        );
        assert_eq!(
            decide(&managed, 8 * GIB, 0, free),
            Placement::Managed {
                device_bytes: 2 * GIB
            }
        );
        // What is left after another grid, rounded down to a granule.
        assert_eq!(
            decide(&managed, 8 * GIB, GIB + 1, free),
            Placement::Managed {
                device_bytes: GIB - MANAGED_GRANULE
            }
        );
        // Never more than the device has free, whatever the budget says.
        let greedy = policy(VolumeMemory::Managed, Some(64 * GIB));
        let Placement::Managed { device_bytes } = decide(&greedy, 64 * GIB, 0, 3 * GIB) else {
            panic!("managed stays managed");
        };
        assert!(device_bytes <= 3 * GIB - DEVICE_RESERVE);
        assert_eq!(device_bytes % MANAGED_GRANULE, 0);
        assert_eq!(
            decide(&greedy, GIB, 0, 0),
            Placement::Managed { device_bytes: 0 }
        );
    }

    #[test]
    fn bytes_read_as_people_write_them() {
        assert_eq!(human_bytes(512), "512 B");
        assert_eq!(human_bytes(3 << 29), "1.50 GiB");
        assert_eq!(human_bytes(12 << 20), "12.0 MiB");
        assert_eq!(human_bytes(8 << 30), "8.00 GiB");
    }

    #[test]
    fn names_are_the_flags_values() {
        let names: Vec<_> = VolumeMemory::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(names, ["device", "zerocopy", "managed", "auto"]);
        for m in VolumeMemory::ALL {
            assert_eq!(m.name().parse::<VolumeMemory>(), Ok(m));
        }
        let err = "pinned".parse::<VolumeMemory>().unwrap_err();
        assert!(err.contains("device, zerocopy, managed, auto"), "{err}");
        assert_eq!(VolumePolicy::default().memory, VolumeMemory::Device);
    }
}
