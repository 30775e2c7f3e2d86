// The small gantry-like case of the feed-axis tests: a bar with heat that moves with the axis and
// a fixed source whose heat follows the feed speed (a feed_power law).
#pragma once

#include <string>

#include "tests/common/case_toml.hpp"

namespace tt::test_toml {

/// A steel bar 1 m along x on [0, 1] with a moving source in it (window 0.2 m) and a fixed
/// feed-speed source in a pad; the axis reciprocates over [0.2, 0.8] at 6 m/min, then stands.
inline std::string gantry_bar(int order, const std::string& scheme = "backward_euler") {
  std::string t = header("bar") + steel();
  t += box_body("bar", "steel", "0.04", "[0.0, 0.0, 0.0]", "[1.0, 0.05, 0.05]");
  t += box_body("pad", "steel", "0.04", "[-0.05, 0.0, 0.0]", "[0.0, 0.05, 0.05]");
  t += "[mesh]\norder = " + std::to_string(order) + "\n";
  t += "[[boundary]]\nname = \"all\"\nrest = true\nselect = [ {} ]\n";
  t += "[thermal]\nscheme = \"" + scheme + "\"\nstep_s = 10.0\noutput_interval_s = 60.0\n";
  t += "[[thermal.convection]]\ngroup = \"all\"\nh_W_m2K = 10.0\nsink_degC = 20.0\n";
  t += "[[thermal.heat_sources]]\nname = \"nut\"\nbody = \"bar\"\nlaw = "
       "\"feed_power\"\npower_ref_W = 30.0\n"
       "ref_feed_m_min = 10.0\nmoving = { window = 0.2 }\n";
  t += "[[thermal.heat_sources]]\nname = \"bearing\"\nbody = \"pad\"\nlaw = "
       "\"feed_power\"\npower_ref_W = 8.0\n"
       "ref_feed_m_min = 10.0\nexponent = 2.0\n";
  t += "[duty_cycle]\nend_s = 600.0\nsegments = [ { start_s = 0.0, speed_rpm = 0.0 } ]\n";
  t += "[feed_axis]\nname = \"X\"\ndirection = \"x\"\nsegments = [ { start_s = 0.0, from = 0.2, to "
       "= 0.8, "
       "feed_m_min = 6.0 }, { start_s = 300.0, position = 0.7 } ]\n";
  t += "[mechanical]\nenabled = false\n";
  return t;
}

}  // namespace tt::test_toml
