// Loads over time from the duty cycle: spindle speed, heat per source, film coefficients and sink
// temperatures, and the time grid whose steps land exactly on every duty-cycle switch.
#pragma once

#include <vector>

#include "core/case_spec.hpp"

namespace tt::solvers {

/// Spindle speed [rpm] on the open interval that contains t (a switch at t belongs to the
/// segment that starts there).
double speed_at(const core::DutyCycle& cycle, double t);

/// Heat of a source [W] at spindle speed n [rpm] (before any temperature dependence); a
/// feed_power source gives 0 here (no feed).
double source_power(const core::HeatSource& source, double speed_rpm);

/// Heat of a source [W] at spindle speed n [rpm] and feed speed v [m/s].
double source_power(const core::HeatSource& source, double speed_rpm, double feed_m_s);

/// Feed speed [m/s] of the axis on the open interval that contains t (0 while it stands, and
/// without a feed axis).
double feed_speed_at(const core::FeedAxis& axis, double t);

/// Position of the axis [m] at t: standing at `from`, or reciprocating from `from` towards `to`
/// and back at the feed speed, restarting at `from` when a segment starts.
double axis_position_at(const core::FeedAxis& axis, double t);

/// Film coefficient [W/(m^2 K)] of a convection entry at spindle speed n [rpm].
double film_coefficient(const core::Convection& convection, double speed_rpm);

/// Linear interpolation in a table, constant beyond its ends.
double table_value(const core::TimeTable& table, double t);

/// The times at which the load can change: duty-cycle and feed-axis segment starts after 0, and
/// the table points of every time-varying sink, inside (0, end).
std::vector<double> switch_times(const core::CaseSpec& spec);

/// The first time after `t` at which the load can change (as switch_times, whatever the end),
/// +inf when none: for stepping a duty cycle that is still being read.
double next_switch(const core::CaseSpec& spec, double t);

/// A speed read at time t [s] [rpm] added to a duty cycle read sample by sample: it holds from t
/// to the next reading (a new segment where it changes; the first segment at 0 takes the first
/// reading), a negative speed is 0, a missing (non-finite) one keeps the last; end becomes t.
void extend_duty_cycle(core::DutyCycle& cycle, double t, double speed_rpm);

/// Throws DataError when a run's first sample, at time t [s], lies more than
/// core::limits::kTimeSteps steps of `step` [s] after t = 0, where a duty cycle read from samples
/// starts and the machine is at its initial temperature: a clock's time (Unix time, a logger's time
/// since power-on), not the time since the run's start, which would be marched to for hours.
void check_first_sample_time(double t, double step);

/// Step end times t_1 < ... < t_N = end: every switch is a step end; between switches the steps
/// are equal and no longer than `max_step`. Throws SolverError beyond core::limits::kTimeSteps.
std::vector<double> time_grid(const core::CaseSpec& spec, double max_step);

/// Output times: multiples of the output interval up to the end, plus the end. Throws
/// SolverError beyond core::limits::kOutputTimes.
std::vector<double> output_times(const core::CaseSpec& spec);

/// Heat delivered by every source from 0 to the end, from the laws alone [J] (no mesh, no solver).
double heat_delivered(const core::CaseSpec& spec);

}  // namespace tt::solvers
