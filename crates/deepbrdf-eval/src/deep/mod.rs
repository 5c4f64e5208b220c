//! DeepBRDF (Hu et al., CGF 2020, §3.2) as a method of the evaluation harness, so it runs
//! through [`crate::harness::run`] exactly like PCA and IPCA (§4, Figs. 3 and 7): the method
//! that trains (or loads) a model per fold and k ([`DeepMethod`]), its codec ([`DeepCodec`]) and
//! the network input each BRDF is mapped to once ([`MappedInput`]).

mod codec;
pub mod highlights;
mod mapped_input;
mod method;

pub use codec::DeepCodec;
pub use mapped_input::{InputCache, MappedInput};
pub use method::{ConfigFor, DeepMethod, FitOrigin, FitRecord};

/// The method's name in tables and plots.
pub const NAME: &str = "DeepBRDF";
