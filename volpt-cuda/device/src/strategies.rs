//! The scheduling strategies (Novák, Havran & Dachsbacher 2010; the thesis's naiveSK,
//! regenerationSK, streamingSK, sortingSK, naiveMK and streamingMK), listed once:
//! [`strategies!`](crate::strategies) generates the host's [`Strategy`] enum and
//! [`export_kernels!`](crate::export_kernels) one kernel per kernel function.
//!
//! `kernels` lists the kernel functions of `strategy`; each function's name is the prefix of its
//! kernels' entry points. Each strategy is `(CamelCase variant, its kernel function, command-line
//! name)`: strategies that differ only in what the host tells the kernel share one function (the
//! multi-kernel strategies: `launch::Stage` carries their `Regeneration`), which halves their
//! share of the kernels' build time and size.

/// Calls `$callback!` with `$args`, the kernel functions and the strategy list.
#[macro_export]
macro_rules! strategies {
    ($callback:path { $($args:tt)* }) => {
        $callback! { $($args)*
            kernels [
                naive_sk regeneration_sk regeneration_warp_sk regeneration_block_sk
                regeneration_2p_sk streaming_sk streaming_sorted_sk sorting_sk multi_kernel
            ]
            strategies [
                (NaiveSk, naive_sk, "naive-sk")
                (RegenerationSk, regeneration_sk, "regeneration-sk")
                (RegenerationWarpSk, regeneration_warp_sk, "regeneration-warp-sk")
                (RegenerationBlockSk, regeneration_block_sk, "regeneration-block-sk")
                (Regeneration2pSk, regeneration_2p_sk, "regeneration-2p-sk")
                (StreamingSk, streaming_sk, "streaming-sk")
                (StreamingSortedSk, streaming_sorted_sk, "streaming-sorted-sk")
                (SortingSk, sorting_sk, "sorting-sk")
                (NaiveMk, multi_kernel, "naive-mk")
                (StreamingMk, multi_kernel, "streaming-mk")
            ]
        }
    };
}

/// The kernels of every strategy for one scene type `VolumeScene<M, B, P, E>` (the box kernels,
/// [`crate::kernel_set::BoxScene`]), exported as `<kernel function>__<m>__<b>__<p>__<e>`: the names
/// must be the parts' `Component::NAME`s, which is how the host finds the entry point of a scene
/// type.
///
/// ```text
/// volpt_device::export_kernels!(my_fog: MyFog, index_matched: NullBoundary,
///                               isotropic: Isotropic, constant: ConstantEnvironment);
/// ```
#[macro_export]
macro_rules! export_kernels {
    ($m:ident: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty, $e:ident: $et:ty $(,)?) => {
        $crate::strategies! { $crate::export_kernels { @each ($m: $mt, $b: $bt, $p: $pt, $e: $et) } }
    };
    (@each $variant:tt kernels [$($s:ident)*] strategies $strategies:tt) => {$(
        $crate::export_kernel! { plain $s BoxScene $variant }
    )*};
}

/// One kernel: kernel function `$s` for scene type `kernel_set::$scene<M, B, P, E>`, exported as
/// `<kernel function>__<m>__<b>__<p>__<e>` (`plain`, the box kernels) or with its kernel set's
/// prefix before it (`lit__...`, `mesh__...`).
#[doc(hidden)]
#[macro_export]
macro_rules! export_kernel {
    (plain $s:ident $scene:ident ($m:ident: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty, $e:ident: $et:ty)) => {
        $crate::export_kernel! { @entry concat!(stringify!($s), "__", stringify!($m), "__", stringify!($b),
            "__", stringify!($p), "__", stringify!($e)), $s $scene ($mt, $bt, $pt, $et) }
    };
    ($set:ident $s:ident $scene:ident ($m:ident: $mt:ty, $b:ident: $bt:ty, $p:ident: $pt:ty, $e:ident: $et:ty)) => {
        $crate::export_kernel! { @entry concat!(stringify!($set), "__", stringify!($s), "__", stringify!($m),
            "__", stringify!($b), "__", stringify!($p), "__", stringify!($e)), $s $scene ($mt, $bt, $pt, $et) }
    };
    (@entry $name:expr, $s:ident $scene:ident ($mt:ty, $bt:ty, $pt:ty, $et:ty)) => {
        const _: () = {
            /// The launch parameters come by value: they live in the kernel's constant bank, where
            /// every instruction can read them, instead of ~40 registers held across the path loop.
            ///
            /// # Safety
            /// The grid, map and buffer addresses in `lp` must be device allocations that stay
            /// alive until the kernel ends, sized for this launch and scene type.
            #[export_name = $name]
            pub unsafe extern "ptx-kernel" fn kernel(
                lp: $crate::LaunchParams<
                    <$crate::kernel_set::$scene<$mt, $bt, $pt, $et> as $crate::launch::SceneAbi>::Params,
                >,
            ) {
                // SAFETY: the grid and map addresses in `lp` are device allocations the host keeps
                // alive.
                let scene = unsafe {
                    <$crate::kernel_set::$scene<$mt, $bt, $pt, $et> as $crate::launch::SceneAbi>::from_params(&lp.scene)
                };
                // SAFETY: `lp`'s buffers are sized for this launch.
                unsafe { $crate::strategy::$s(&scene, &lp) }
            }
        };
    };
}

macro_rules! define_strategy {
    (kernels [$($kernel:ident)*] strategies [$(($camel:ident, $s:ident, $cli:literal))*]) => {
        /// A GPU scheduling strategy: who traces which path, and how results reach the film.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        #[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
        pub enum Strategy {
            $(#[cfg_attr(feature = "clap", value(name = $cli))] $camel,)*
        }

        impl Strategy {
            pub const ALL: &'static [Strategy] = &[$(Strategy::$camel),*];

            /// The entry prefixes of the kernel functions, each once: a scene type has one kernel
            /// per prefix.
            pub const KERNELS: &'static [&'static str] = &[$(stringify!($kernel)),*];

            /// The name users type: `--strategy naive-sk`.
            pub fn name(self) -> &'static str {
                match self {
                    $(Strategy::$camel => $cli,)*
                }
            }

            /// The prefix of this strategy's kernel entry points (one of [`Self::KERNELS`]).
            pub fn entry_prefix(self) -> &'static str {
                match self {
                    $(Strategy::$camel => stringify!($s),)*
                }
            }
        }
    };
}

strategies!(define_strategy {});

impl core::fmt::Display for Strategy {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}
