//! The navigation layer's tests: the mechanization against independent values and the exact
//! truth; the error dynamics against the navigation equations they linearize.

mod car;
mod ensemble;
mod error_state;
mod mechanization;
mod nhc;
mod propagation;
mod scale;
mod simulated_logs;
