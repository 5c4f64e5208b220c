//! The command-line arguments that several commands share, one group a file: the data
//! selection ([`data`]), `--device` ([`device`]), `--model` ([`model`]), a real measurement
//! given as a material ([`measurement`]), the recovery
//! `--network` ([`network`]), an edit's attribute changes ([`edit`]), `--corpus` ([`corpus`]),
//! the scene ([`scene`]), a figure's rendering ([`figure`]), `--refine` ([`refine`]) and
//! `--time-limit` ([`time_limit`]).

pub mod corpus;
pub mod data;
pub mod device;
pub mod edit;
pub mod figure;
pub mod measurement;
pub mod model;
pub mod network;
pub mod refine;
pub mod scene;
pub mod time_limit;
