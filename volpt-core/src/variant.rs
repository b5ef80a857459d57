//! The variant registry: every value of every variant axis, and the type that implements it.
//!
//! A scene is a `VolumeScene<M, B, P, E>`; each of its four parts is chosen from one axis below.
//! This list is the only place the axes are enumerated: the render factory's dispatch, the GPU
//! kernels' instantiation and the kernels' entry names are all generated from it (pbrt-v4's
//! `ForEachType` idea, with `macro_rules!`). Adding an axis value is one line here, beside the
//! part's own file.
//!
//! [`variants!`](crate::variants) calls a macro of the caller with the axes and with the cartesian
//! product of their values:
//!
//! ```text
//! volpt_core::variants!('a => my_macro { extra tokens });
//! // expands to
//! my_macro! { extra tokens
//!     axes {
//!         medium [(Homogeneous, homogeneous, HomogeneousMedium) ...]
//!         boundary [...] phase [...] environment [...]
//!     }
//!     variants [
//!         [(Homogeneous, homogeneous, HomogeneousMedium) (IndexMatched, index_matched, NullBoundary)
//!          (Isotropic, isotropic, Isotropic) (Constant, constant, ConstantEnvironment)]
//!         ...
//!     ]
//! }
//! ```
//!
//! Each value is `(CamelCase name, snake_case name, type)`. The snake-case name is the part's
//! [`Component::NAME`](crate::abi::Component::NAME), which a generic part composes from its type
//! parameters' names ([`crate::abi::name`]), and so appears in kernel entry points; the CamelCase
//! name (the factory's enum variants) is the same words. Tests check both, so neither can drift
//! from the type; types that borrow grids take the caller's lifetime `'a` (`'_` inside function
//! bodies, `'static` for type-level questions).

/// Calls `$callback!` with the registry's axes and every combination of their values; see the
/// [module documentation](crate::variant).
#[macro_export]
macro_rules! variants {
    ($lt:lifetime => $callback:path { $($args:tt)* }) => {
        $crate::variants! { @mul
            { ($callback) { $($args)* } axes {
                medium [
                    (Homogeneous, homogeneous, $crate::HomogeneousMedium)
                    (GridDensityConstantAlbedoDenseTrilinear,
                        grid_density__constant_albedo__dense_trilinear,
                        $crate::GridMedium<$lt, $crate::ConstantAlbedo>)
                    (GridDensityGridAlbedoDenseTrilinear, grid_density__grid_albedo__dense_trilinear,
                        $crate::GridMedium<$lt, $crate::GridAlbedo<$lt>>)
                    (GridDensityGridAlbedoAnyLayout, grid_density__grid_albedo__any_layout,
                        $crate::GridMedium<$lt, $crate::GridAlbedo<$lt, $crate::AnyLayout>,
                        $crate::AnyLayout>)
                    (GridDensityGridAlbedoTextureTrilinear,
                        grid_density__grid_albedo__texture_trilinear,
                        $crate::GridMedium<$lt, $crate::GridAlbedo<$lt, $crate::TextureTrilinear>,
                        $crate::TextureTrilinear>)
                    (Chromatic, chromatic, $crate::ChromaticMedium<$lt>)
                ]
                boundary [
                    (IndexMatched, index_matched, $crate::NullBoundary)
                    (SmoothDielectric, smooth_dielectric, $crate::SmoothDielectric)
                    (RoughDielectric, rough_dielectric, $crate::RoughDielectric)
                ]
                phase [
                    (Isotropic, isotropic, $crate::Isotropic)
                    (HenyeyGreenstein, henyey_greenstein, $crate::HenyeyGreenstein)
                ]
                environment [
                    (Constant, constant, $crate::ConstantEnvironment)
                    (LatLong, lat_long, $crate::LatLongEnvironment<$lt>)
                ]
            } }
            [] [[]]
        }
    };

    // The product is built one axis at a time: every partial combination in the accumulator is
    // extended by every value of the next axis. Partial combinations are nested groups
    // `[[[[] m] b] p]`, because `macro_rules!` cannot splice a repeated group into another
    // repetition; they are flattened at the end.
    (@mul { $cb:tt $args:tt axes { $($axis:ident $values:tt)* } } $out:tt $acc:tt) => {
        $crate::variants! { @step { $cb $args axes { $($axis $values)* } } [] $acc [$($values)*] }
    };
    (@step $ctx:tt [$($out:tt)*] [$a:tt $($acc:tt)*] [[$($v:tt)*] $($rest:tt)*]) => {
        $crate::variants! { @step $ctx [$($out)* $([$a $v])*] [$($acc)*] [[$($v)*] $($rest)*] }
    };
    (@step $ctx:tt $out:tt [] [$done:tt $next:tt $($rest:tt)*]) => {
        $crate::variants! { @step $ctx [] $out [$next $($rest)*] }
    };
    (@step { ($cb:path) { $($args:tt)* } axes $axes:tt } [$([[[[[] $m:tt] $b:tt] $p:tt] $e:tt])*] [] [$last:tt]) => {
        $cb! { $($args)* axes $axes variants [$([$m $b $p $e])*] }
    };
}

/// The registry's names of one variant's parts: `[medium, boundary, phase, environment]`.
pub type VariantNames = [&'static str; 4];

macro_rules! registry_names {
    (axes $axes:tt variants [$([$(($camel:ident, $snake:ident, $ty:ty))*])*]) => {
        /// Every variant of the registry by its parts' names, in registry order: what tests and
        /// tables enumerate instead of counting by hand.
        pub const NAMES: &[VariantNames] = &[$([$(stringify!($snake)),*]),*];
    };
}

variants!('static => registry_names {});

/// How many variants the registry has (the product of its axes' lengths).
pub const COUNT: usize = NAMES.len();

#[cfg(test)]
mod tests {
    use super::COUNT;
    use crate::abi::Component;

    /// `(registry name, Component::NAME)` of every part of every variant, and `(CamelCase,
    /// snake_case)` of every axis value.
    macro_rules! registry_facts {
        (axes { $($axis:ident [$(($c:ident, $s:ident, $t:ty))*])* }
         variants [$([$(($camel:ident, $snake:ident, $ty:ty))*])*]) => {
            fn facts() -> [[(&'static str, &'static str); 4]; COUNT] {
                [$([$((stringify!($snake), <$ty as Component>::NAME)),*]),*]
            }

            fn spellings() -> &'static [(&'static str, &'static str)] {
                &[$($((stringify!($c), stringify!($s)),)*)*]
            }
        };
    }

    variants!('static => registry_facts {});

    #[test]
    fn registry_names_are_the_components_names() {
        for parts in facts() {
            for (registry, component) in parts {
                assert_eq!(registry, component);
            }
        }
    }

    #[test]
    fn camel_case_names_are_the_snake_case_names_words() {
        for &(camel, snake) in spellings() {
            // Each word of the snake-case name, its first letter upper case, in order.
            let mut rest = camel.as_bytes();
            for word in snake.split('_').filter(|w| !w.is_empty()) {
                let word = word.as_bytes();
                assert!(
                    rest.len() >= word.len()
                        && rest[0] == word[0].to_ascii_uppercase()
                        && rest[1..word.len()] == word[1..],
                    "{camel} is not {snake}"
                );
                rest = &rest[word.len()..];
            }
            assert!(rest.is_empty(), "{camel} is not {snake}");
        }
    }

    #[test]
    fn the_names_are_the_facts() {
        assert_eq!(
            super::NAMES,
            facts().map(|parts| parts.map(|(name, _)| name))
        );
    }

    #[test]
    fn every_combination_appears_once() {
        let variants = facts().map(|parts| parts.map(|(name, _)| name));
        for (i, a) in variants.iter().enumerate() {
            for b in &variants[i + 1..] {
                assert_ne!(a, b);
            }
        }
        assert!(variants.contains(&[
            "grid_density__grid_albedo__dense_trilinear",
            "rough_dielectric",
            "henyey_greenstein",
            "lat_long"
        ]));
    }
}
