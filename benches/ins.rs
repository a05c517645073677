//! The three-axis ensemble's speed on the default drive (600 s at 200 Hz, 600 fixes): one
//! realization's time with the covariance propagated per covariance interval (what
//! `ins::ensemble` runs) and per IMU step through dense 15×15 products (the reference), each the
//! median of repeated runs with the minimum and maximum, in the thread's CPU time (the machine
//! may be shared); what the sensors and the mechanization
//! alone cost; and optionally a whole ensemble through `ins::ensemble::run`.
//!
//! Run with `cargo bench --bench ins` (options: `-- --realizations N --repeats R --ensemble M
//! --duration S --profile M`; defaults N = 4 per run, R = 5, no ensemble, the whole 600 s drive; `--profile M` runs M
//! realizations and nothing else, for `perf record`).

use std::hint::black_box;
use std::time::Instant;

use accelcal::config::ins::InsConfig;
use accelcal::ins::ensemble::{self, Track, error};
use accelcal::ins::filter::Propagation;
use accelcal::ins::mech;
use accelcal::ins::setup::Scenario;
use accelcal::ins::simulated_logs::fix;

fn arg(name: &str) -> Option<String> {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .cloned()
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// This thread's CPU time, s: on a machine shared with other work, what a run cost rather than
/// how long it waited.
fn thread_cpu_s() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `t` is a valid timespec for the call to fill.
    unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// The median rate (realizations per CPU second) of `once`, a run of `n` realizations, on one
/// thread.
fn measure(label: &str, repeats: usize, n: u64, mut once: impl FnMut(u64)) -> f64 {
    once(0);
    let mut rates: Vec<f64> = (0..repeats)
        .map(|r| {
            let t = thread_cpu_s();
            for l in 0..n {
                once(r as u64 * n + l);
            }
            n as f64 / (thread_cpu_s() - t)
        })
        .collect();
    let lo = rates.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = rates.iter().cloned().fold(0.0, f64::max);
    let med = median(&mut rates);
    println!(
        "{label:<44} median {med:>8.2} realizations/s = {:>7.1} ms each (min {lo:.2}, max {hi:.2}; {repeats} runs of {n})",
        1e3 / med
    );
    med
}

/// Realization `index` as `ins::ensemble::realization` runs it, with the covariance propagated
/// as `propagation` says; the sum of its NEES before each update and NIS.
fn realization(scenario: &Scenario, track: &Track, index: u64, propagation: Propagation) -> f64 {
    let drive = scenario.drive();
    let (mut imu, ekf) = accelcal::ins::ensemble::start::<15>(scenario, track, index);
    let mut ekf = ekf.with_propagation(propagation);
    let g = &scenario.filter_gnss;
    let dt = 1.0 / scenario.imu_rate_hz;
    let mut sum = 0.0;
    for (k, (inc, pva)) in track.steps.iter().enumerate() {
        ekf.propagate(&imu.read(inc));
        if (k + 1) % scenario.imu_steps_per_fix != 0 {
            continue;
        }
        let mut reading = fix(scenario, &drive, &mut imu, (k + 1) as f64 * dt, pva);
        reading.position_sigma_m = g.position_sigma_m;
        reading.velocity_sigma_m_s = g.velocity_sigma_m_s;
        let e = error(&ekf, pva, &imu);
        sum += e.dot(&ekf.covariance.cholesky().unwrap().solve(&e));
        sum += ekf.update(&reading).unwrap().nis;
    }
    sum
}

fn main() {
    let n: u64 = arg("--realizations")
        .and_then(|v| v.parse().ok())
        .unwrap_or(4);
    let repeats: usize = arg("--repeats").and_then(|v| v.parse().ok()).unwrap_or(5);
    let mut c = InsConfig::default();
    if let Some(d) = arg("--duration").and_then(|v| v.parse().ok()) {
        c.drive.duration_s = d;
    }
    let scenario = Scenario::from_config(&c).expect("the default scenario is valid");
    let t = Instant::now();
    let track = Track::of(&scenario);
    println!(
        "truth of the {} s drive ({} steps): {:.2} s",
        scenario.duration_s,
        track.steps.len(),
        t.elapsed().as_secs_f64()
    );
    if let Some(m) = arg("--profile").and_then(|v| v.parse().ok()) {
        // Only the realizations, for `perf record`.
        for l in 0..m {
            let r = ensemble::realization::<15>(&scenario, &track, l);
            assert!(r.is_ok());
            black_box(&r);
        }
        return;
    }
    measure("sensors only (imu.read)", repeats, n, |l| {
        let mut imu = scenario.imu(l);
        let s: f64 = track.steps.iter().map(|(inc, _)| imu.read(inc).dt_s).sum();
        black_box(s);
    });
    measure("sensors and mechanization", repeats, n, |l| {
        let mut imu = scenario.imu(l);
        let mut pva = track.start;
        let mut before = None;
        for (inc, _) in &track.steps {
            let now = imu.read(inc);
            pva = mech::step(&pva, &before.unwrap_or(now), &now);
            before = Some(now);
        }
        black_box(pva);
    });
    let fast = measure(
        "realization (ins::ensemble::realization)",
        repeats,
        n,
        |l| {
            let r = ensemble::realization::<15>(&scenario, &track, l);
            assert!(r.is_ok());
            black_box(&r);
        },
    );
    let dense = measure("realization, dense per-step covariance", repeats, n, |l| {
        black_box(realization(&scenario, &track, l, Propagation::Dense));
    });
    println!("speed-up over the dense reference: {:.1}×", fast / dense);
    if let Some(m) = arg("--ensemble").and_then(|v| v.parse().ok()) {
        let t = Instant::now();
        let outcome = ensemble::run::<15>(&scenario, &track, m);
        // Wall time: the figure the ensemble's user waits for.
        let run_s = t.elapsed().as_secs_f64();
        assert!(outcome.is_ok());
        black_box(&outcome);
        println!(
            "ensemble of {m} on {} threads: {run_s:.1} s ({:.1} ms a realization), {} fixes each",
            rayon::current_num_threads(),
            1e3 * run_s / m as f64,
            track.steps.len() / scenario.imu_steps_per_fix
        );
    }
}
