pub mod batch;
pub mod context;
pub mod executor;
pub mod runner;
pub mod sequence;
pub mod stream;
