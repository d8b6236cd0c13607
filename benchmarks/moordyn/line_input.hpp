// The MoorDyn input file of the benchmark line that both MoorDyn harnesses run (side_by_side.cpp,
// work_precision.cpp): one 20 m line "tether" (0.008 m, 0.07 kg/m, EA 1e5 N, Cd 1.2, Ca 1.0,
// CdAx 0.008) from a fixed point to a coupled one, in 1000 m of water, with an optional uniform
// current (current_profile.txt beside it). Positions are kelp's NED; MoorDyn's z is up.
#pragma once

#include <cstdio>
#include <fstream>
#include <string>

namespace kelp_bench {

struct LineInput {
  std::string title;            // the file's second line
  double internal_damping = 0;  // BA/-zeta: > 0 N s, < 0 a damping ratio
  double start[3] = {0, 0, 0};  // the fixed end, NED [m]
  double end[3] = {0, 0, 0};    // the coupled end at t = 0, NED [m]
  int segments = 20;
  const char* scheme = "RK4";  // tScheme
  double dt = 1e-4;            // dtM [s]
  double current = 0;          // uniform current along x [m/s]; 0: none
};

// Writes the line's input file at `path` (and, with a current, `dir`/current_profile.txt, which
// MoorDyn reads from the input file's directory `dir`).
inline void write_moordyn_line(const LineInput& l, const std::string& dir,
                               const std::string& path) {
  std::ofstream o(path);
  char num[256];
  o << "--------------------- MoorDyn Input File ------------------------------------\n"
    << l.title
    << "\n"
       "----------------------- LINE TYPES ------------------------------------------\n"
       "TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    "
       "CaAx\n"
       "(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     "
       "(-)\n";
  std::snprintf(num, sizeof num,
                "tether     0.008   0.07       1.0e5      %.17g   0.0   1.2    "
                "1.0    0.008   0.0\n",
                l.internal_damping);
  o << num
    << "---------------------- POINT PROPERTIES --------------------------------\n"
       "ID    Type      X       Y       Z       Mass   Volume  CdA    Ca\n"
       "(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)\n";
  std::snprintf(num, sizeof num, "1     Fixed     %.17g %.17g %.17g 0 0 0 0\n", l.start[0],
                l.start[1], -l.start[2]);
  o << num;
  std::snprintf(num, sizeof num, "2     Coupled   %.17g %.17g %.17g 0 0 0 0\n", l.end[0], l.end[1],
                -l.end[2]);
  o << num
    << "---------------------- LINES ----------------------------------------\n"
       "ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs\n"
       "(#)   (name)     (#)      (#)       (m)       (-)     (-)\n"
       "1     tether     1        2         20.0      "
    << l.segments
    << "      -\n"
       "---------------------- OPTIONS -----------------------------------------\n"
       "0             writeLog\n"
    << l.scheme << "           tScheme\n";
  std::snprintf(num, sizeof num, "%.17g  dtM\n", l.dt);
  o << num
    << "1025.0        WtrDnsty\n"
       "9.80665       g\n"
       "1000.0        WtrDpth\n"
       "3.0e6         kBot\n"
       "3.0e5         cBot\n"
       "0.5 dtIC\n300.0 TmaxIC\n1e-9 threshIC\n1.0 CdScaleIC\n"
    << (l.current != 0 ? "1             Currents\n" : "")
    << "1             disableOutput\n"
       "1             disableOutTime\n"
       "------------------------- need this line --------------------------------------\n";
  if (l.current != 0) {
    // A uniform current (MoorDyn's steady current profile: Currents = 1).
    std::ofstream cp(dir + "/current_profile.txt");
    cp << "--------------------- MoorDyn steady currents File ------------------------------\n"
          "uniform current\n"
          "z (m), ux (m/s), uy (m/s), uz (m/s)\n";
    cp << "-1000.0 " << l.current << " 0 0\n0.0 " << l.current << " 0 0\n";
  }
}

}  // namespace kelp_bench
