//! Reproductions of the theses' tables: each module holds the published
//! numbers (with their seed line numbers), the runs that measure ours, and the
//! side-by-side output.

pub mod flight_tables;
pub mod table_4_1;
pub mod table_4_2;
pub mod table_4_3;
pub mod table_4_4;
pub mod timing;
