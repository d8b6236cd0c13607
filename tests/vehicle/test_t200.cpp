// The Blue Robotics T200 from its published data (kelp/vehicle/t200.hpp) and the thruster chain's
// facing and supply voltage (kelp/vehicle/thrusters.hpp).
#include <catch2/catch.hpp>
#include <cmath>

#include "kelp/vehicle/presets.hpp"
#include "kelp/vehicle/t200.hpp"
#include "kelp/vehicle/thrusters.hpp"

namespace kv = kelp::vehicle;

namespace {

// Blue Robotics, "T200 Public Performance Data 10-20V (September 2019)",
// https://cad.bluerobotics.com/T200-Public-Performance-Data-10-20V-September-2019.xlsx: the
// sheets at 10, 12, 16, 18 and 20 V, every row: PWM 1100 to 1900 µs in 4 µs steps (201 rows),
// force in 0.01 kgf (negative: reverse) and supply current in 0.01 A, as published (the sheet's
// RPM, power and efficiency columns are left out). The 14 V sheet was not reachable; its
// full-throttle thrusts are below.
struct Sheet {
  double volts;
  int thrust[201];   // [0.01 kgf]
  int current[201];  // [0.01 A]
};
const Sheet kSheets[] = {
    {10.0,
     {
         -231, -230, -230, -228, -222, -218, -216, -213, -211, -205, -204, -199, -195, -193, -189,
         -184, -181, -179, -176, -171, -168, -165, -162, -159, -156, -154, -150, -147, -144, -141,
         -136, -133, -132, -129, -126, -122, -119, -117, -114, -110, -108, -106, -102, -99,  -97,
         -93,  -91,  -88,  -85,  -83,  -80,  -78,  -75,  -72,  -70,  -67,  -65,  -63,  -61,  -58,
         -55,  -53,  -51,  -49,  -47,  -44,  -42,  -40,  -38,  -35,  -34,  -31,  -29,  -28,  -25,
         -24,  -21,  -20,  -18,  -16,  -15,  -14,  -12,  -10,  -9,   -7,   -6,   -5,   -5,   -3,
         0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    0,    0,    0,    4,    5,    7,    8,    9,    11,   13,   15,   16,
         18,   20,   22,   24,   26,   29,   31,   34,   36,   39,   41,   44,   47,   49,   52,
         55,   58,   61,   64,   68,   70,   73,   76,   80,   83,   85,   89,   92,   95,   98,
         97,   105,  108,  111,  117,  118,  121,  124,  127,  131,  136,  141,  143,  148,  152,
         155,  158,  162,  166,  169,  173,  177,  180,  185,  188,  191,  199,  200,  206,  209,
         212,  217,  221,  227,  230,  236,  241,  245,  248,  255,  258,  262,  265,  269,  274,
         277,  282,  288,  289,  292,  293,
     },
     {
         1362, 1363, 1345, 1320, 1281, 1250, 1214, 1196, 1163, 1132, 1100, 1080, 1045, 1020, 990,
         956,  929,  910,  880,  850,  830,  805,  771,  757,  730,  710,  682,  660,  648,  620,
         600,  580,  560,  540,  520,  500,  484,  464,  450,  430,  410,  390,  373,  360,  350,
         330,  320,  300,  290,  280,  260,  240,  230,  210,  200,  190,  180,  170,  160,  150,
         140,  130,  120,  120,  110,  100,  90,   80,   80,   70,   70,   60,   50,   50,   40,
         40,   40,   30,   22,   20,   20,   20,   20,   10,   10,   10,   5,    5,    5,    5,
         0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    0,    0,    0,    5,    5,    5,    10,   10,   10,   10,   20,   20,
         20,   20,   30,   30,   40,   40,   47,   50,   50,   60,   70,   70,   80,   83,   94,
         100,  110,  120,  130,  140,  150,  150,  160,  180,  190,  200,  210,  220,  230,  243,
         270,  280,  290,  310,  330,  340,  350,  370,  384,  400,  420,  440,  450,  470,  490,
         510,  530,  550,  570,  590,  609,  630,  650,  673,  690,  713,  740,  760,  790,  810,
         833,  864,  889,  914,  940,  970,  1000, 1020, 1050, 1079, 1104, 1135, 1160, 1190, 1228,
         1244, 1280, 1313, 1340, 1362, 1360,
     }},
    {12.0,
     {
         -290, -292, -289, -283, -279, -276, -272, -267, -260, -259, -256, -249, -244, -243, -239,
         -234, -230, -225, -223, -218, -214, -210, -207, -201, -198, -195, -188, -185, -181, -178,
         -173, -166, -165, -161, -156, -153, -149, -147, -144, -140, -137, -133, -129, -128, -122,
         -119, -115, -112, -108, -104, -102, -99,  -96,  -93,  -90,  -87,  -83,  -79,  -77,  -74,
         -72,  -69,  -66,  -64,  -60,  -57,  -54,  -52,  -49,  -47,  -44,  -42,  -39,  -37,  -34,
         -32,  -29,  -27,  -24,  -23,  -20,  -18,  -16,  -15,  -12,  -11,  -9,   -7,   -6,   -5,
         -4,   0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    0,    0,    4,    5,    7,    10,   11,   13,   15,   18,   20,   22,
         25,   28,   31,   33,   37,   39,   43,   46,   49,   52,   55,   59,   63,   65,   68,
         71,   76,   79,   83,   86,   89,   93,   97,   100,  104,  108,  114,  116,  120,  123,
         128,  131,  135,  140,  143,  148,  153,  156,  163,  167,  171,  177,  182,  185,  191,
         192,  196,  203,  209,  213,  218,  224,  227,  233,  240,  246,  251,  256,  262,  265,
         271,  278,  284,  287,  293,  301,  304,  308,  316,  323,  326,  332,  338,  340,  345,
         350,  357,  364,  371,  369,  371,
     },
     {
         1703, 1708, 1676, 1652, 1608, 1569, 1531, 1500, 1451, 1417, 1382, 1346, 1308, 1280, 1240,
         1200, 1166, 1131, 1110, 1074, 1050, 1011, 984,  950,  920,  890,  860,  830,  800,  770,
         740,  710,  690,  660,  640,  620,  599,  577,  550,  532,  517,  490,  470,  456,  430,
         410,  390,  373,  360,  340,  330,  310,  298,  280,  270,  241,  230,  210,  200,  190,
         180,  170,  160,  150,  131,  130,  120,  110,  100,  90,   80,   80,   70,   60,   50,
         50,   41,   40,   40,   30,   29,   20,   20,   20,   10,   10,   10,   5,    5,    5,
         5,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    0,    0,    5,    5,    5,    10,   10,   10,   10,   20,   20,   20,
         30,   30,   40,   40,   50,   50,   60,   70,   70,   80,   80,   100,  100,  110,  120,
         130,  140,  150,  160,  170,  180,  200,  210,  220,  230,  250,  280,  290,  300,  320,
         330,  350,  367,  380,  400,  420,  440,  460,  480,  500,  520,  540,  569,  580,  600,
         630,  650,  670,  700,  720,  750,  780,  800,  832,  864,  890,  924,  950,  982,  1014,
         1045, 1072, 1110, 1132, 1162, 1201, 1237, 1261, 1304, 1344, 1370, 1411, 1440, 1476, 1513,
         1552, 1587, 1630, 1674, 1686, 1691,
     }},
    {16.0,
     {
         -407, -405, -402, -396, -390, -387, -382, -380, -375, -371, -366, -359, -352, -345, -340,
         -331, -325, -320, -311, -304, -299, -294, -286, -282, -277, -271, -266, -258, -255, -251,
         -245, -238, -235, -228, -224, -220, -212, -208, -202, -198, -194, -186, -181, -176, -170,
         -167, -161, -156, -151, -149, -144, -140, -135, -130, -126, -120, -116, -112, -110, -105,
         -102, -98,  -94,  -90,  -87,  -82,  -78,  -74,  -72,  -68,  -65,  -62,  -58,  -54,  -51,
         -48,  -44,  -42,  -39,  -35,  -32,  -29,  -26,  -24,  -21,  -18,  -15,  -13,  -10,  -9,
         -7,   -5,   -4,   0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    4,    5,    8,    10,   13,   15,   18,   22,   25,   29,   32,   36,
         40,   44,   47,   51,   56,   60,   64,   68,   72,   78,   82,   87,   91,   95,   99,
         103,  110,  114,  118,  124,  128,  133,  139,  144,  148,  154,  159,  165,  169,  176,
         182,  188,  193,  199,  205,  212,  218,  222,  228,  238,  243,  252,  258,  265,  273,
         276,  284,  289,  298,  305,  311,  317,  322,  330,  337,  342,  351,  361,  368,  374,
         382,  389,  396,  406,  415,  425,  430,  438,  451,  453,  465,  471,  479,  484,  493,
         501,  508,  514,  518,  522,  525,
     },
     {
         2430, 2430, 2378, 2325, 2264, 2207, 2146, 2098, 2044, 1990, 1932, 1874, 1811, 1753, 1700,
         1645, 1596, 1548, 1498, 1443, 1404, 1355, 1310, 1274, 1230, 1193, 1159, 1120, 1080, 1050,
         1027, 990,  950,  920,  890,  860,  820,  790,  757,  719,  689,  653,  629,  600,  575,
         550,  530,  500,  480,  460,  440,  420,  398,  370,  358,  339,  320,  300,  284,  270,
         240,  230,  210,  200,  190,  170,  160,  150,  140,  130,  120,  110,  100,  90,   80,
         70,   66,   56,   50,   40,   40,   37,   30,   20,   20,   20,   10,   10,   10,   5,
         5,    5,    5,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    5,    5,    5,    5,    10,   10,   10,   20,   20,   20,   30,   40,
         40,   50,   50,   60,   70,   80,   80,   90,   100,  110,  120,  130,  145,  150,  160,
         180,  200,  210,  220,  240,  260,  280,  290,  310,  330,  350,  370,  390,  410,  430,
         458,  470,  500,  520,  542,  569,  590,  619,  640,  670,  700,  740,  770,  804,  840,
         870,  903,  934,  969,  1001, 1040, 1068, 1090, 1130, 1164, 1193, 1238, 1279, 1314, 1354,
         1399, 1446, 1486, 1540, 1586, 1641, 1697, 1742, 1800, 1850, 1913, 1959, 2015, 2067, 2113,
         2180, 2238, 2281, 2328, 2390, 2383,
     }},
    {18.0,
     {
         -459, -454, -453, -448, -442, -435, -435, -417, -418, -411, -404, -399, -391, -386, -381,
         -371, -368, -356, -354, -342, -336, -327, -319, -309, -303, -296, -288, -284, -278, -270,
         -266, -259, -253, -248, -242, -236, -232, -225, -221, -216, -211, -204, -200, -194, -188,
         -181, -176, -172, -166, -161, -156, -152, -147, -142, -138, -133, -127, -122, -117, -113,
         -108, -105, -101, -97,  -93,  -89,  -86,  -81,  -77,  -74,  -70,  -67,  -64,  -60,  -56,
         -53,  -49,  -46,  -43,  -40,  -37,  -34,  -30,  -27,  -24,  -21,  -18,  -15,  -13,  -10,
         -8,   -6,   -5,   0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    5,    7,    9,    12,   15,   18,   21,   25,   29,   32,   36,   39,
         43,   47,   51,   55,   59,   63,   67,   70,   76,   80,   84,   88,   92,   97,   102,
         108,  113,  118,  122,  128,  132,  138,  142,  149,  154,  160,  168,  174,  179,  184,
         192,  197,  204,  208,  217,  222,  228,  236,  243,  250,  259,  264,  274,  279,  287,
         293,  301,  310,  315,  321,  327,  339,  346,  354,  363,  372,  379,  392,  402,  414,
         421,  432,  441,  454,  467,  469,  486,  492,  502,  512,  521,  529,  538,  550,  560,
         567,  577,  582,  590,  598,  602,
     },
     {
         2822, 2791, 2731, 2662, 2604, 2538, 2480, 2403, 2353, 2278, 2221, 2150, 2061, 2017, 1951,
         1885, 1823, 1757, 1712, 1634, 1580, 1519, 1469, 1416, 1368, 1327, 1283, 1236, 1199, 1158,
         1132, 1100, 1065, 1027, 997,  955,  920,  887,  854,  819,  777,  739,  700,  665,  630,
         600,  575,  550,  523,  500,  479,  459,  430,  410,  390,  368,  340,  330,  310,  290,
         273,  250,  230,  214,  200,  190,  176,  160,  150,  140,  130,  120,  110,  100,  80,
         80,   70,   63,   53,   50,   40,   40,   30,   30,   20,   20,   20,   10,   10,   10,
         5,    5,    5,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    5,    5,    5,    10,   10,   10,   20,   20,   20,   30,   30,   40,
         40,   50,   50,   60,   70,   80,   88,   100,  100,  120,  130,  138,  150,  160,  170,
         183,  200,  210,  230,  247,  270,  290,  307,  324,  340,  360,  380,  407,  429,  452,
         472,  498,  520,  547,  570,  597,  625,  655,  687,  728,  764,  800,  840,  880,  915,
         948,  990,  1020, 1053, 1081, 1118, 1158, 1188, 1229, 1259, 1312, 1350, 1404, 1449, 1509,
         1555, 1614, 1666, 1732, 1789, 1845, 1927, 1972, 2038, 2103, 2160, 2229, 2287, 2355, 2423,
         2477, 2548, 2604, 2674, 2722, 2757,
     }},
    {20.0,
     {
         -504, -496, -492, -484, -479, -474, -468, -458, -446, -440, -435, -423, -416, -412, -402,
         -396, -389, -381, -371, -366, -356, -348, -336, -329, -316, -313, -300, -294, -287, -278,
         -274, -267, -260, -254, -250, -244, -240, -231, -226, -220, -214, -211, -204, -197, -191,
         -186, -180, -173, -167, -164, -158, -152, -147, -141, -137, -132, -127, -122, -117, -111,
         -107, -102, -99,  -94,  -91,  -88,  -83,  -78,  -75,  -72,  -69,  -66,  -63,  -59,  -56,
         -53,  -50,  -47,  -44,  -41,  -39,  -36,  -32,  -29,  -26,  -24,  -20,  -17,  -15,  -12,
         -9,   -7,   -5,   -4,   0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    6,    9,    11,   15,   18,   21,   25,   29,   32,   36,   39,   43,
         47,   50,   54,   57,   61,   64,   66,   70,   74,   78,   82,   86,   89,   93,   98,
         102,  106,  112,  117,  122,  128,  131,  138,  144,  153,  158,  164,  174,  180,  185,
         192,  198,  207,  212,  220,  225,  233,  244,  252,  261,  266,  276,  283,  291,  299,
         306,  313,  322,  328,  336,  344,  355,  364,  372,  385,  396,  410,  421,  433,  442,
         455,  470,  482,  493,  502,  514,  520,  539,  552,  562,  571,  582,  593,  606,  613,
         626,  636,  646,  655,  662,  672,
     },
     {
         3217, 3137, 3060, 2967, 2904, 2826, 2756, 2674, 2582, 2516, 2445, 2354, 2308, 2246, 2163,
         2100, 2030, 1965, 1900, 1836, 1775, 1711, 1643, 1581, 1523, 1474, 1412, 1366, 1322, 1269,
         1236, 1201, 1157, 1127, 1084, 1054, 1022, 977,  940,  896,  860,  829,  787,  748,  703,
         660,  630,  597,  570,  541,  516,  488,  460,  431,  409,  381,  358,  332,  309,  290,
         271,  246,  230,  210,  200,  184,  170,  159,  150,  130,  129,  120,  105,  100,  88,
         80,   70,   70,   60,   50,   50,   40,   40,   30,   20,   20,   20,   10,   10,   10,
         5,    5,    5,    5,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,    0,
         0,    0,    0,    5,    5,    5,    10,   10,   10,   20,   20,   20,   30,   40,   40,
         50,   50,   60,   70,   70,   80,   80,   96,   100,  110,  120,  130,  140,  151,  160,
         179,  190,  206,  220,  237,  263,  282,  306,  328,  349,  372,  398,  426,  459,  483,
         508,  539,  566,  590,  620,  650,  687,  730,  772,  814,  853,  892,  929,  970,  1000,
         1043, 1077, 1112, 1147, 1178, 1223, 1262, 1300, 1347, 1400, 1446, 1507, 1564, 1627, 1683,
         1751, 1807, 1869, 1930, 1998, 2063, 2121, 2188, 2249, 2320, 2380, 2455, 2519, 2595, 2662,
         2755, 2812, 2895, 2974, 3046, 3121,
     }},
};
constexpr double kKgf = 9.80665;
double command_of_row(int k) { return (1100.0 + 4.0 * k - 1500.0) / 400.0; }

}  // namespace

TEST_CASE("T200: every published data point within 10 % (below 0.3 kgf: within 0.03 kgf)",
          "[vehicle][t200]") {
  // Thrusts from 0.3 kgf up are judged relative to the reading, smaller ones (and the zeros of
  // the dead band) by their absolute error against 0.3 kgf: 10 % of 0.3 kgf = 0.03 kgf.
  double max_rel[2] = {0, 0}, sum_sq[2] = {0, 0};
  int n[2] = {0, 0}, checked = 0;
  for (const Sheet& sheet : kSheets) {
    for (int k = 0; k < 201; ++k) {
      const double u = command_of_row(k);
      const double data = sheet.thrust[k] / 100.0;
      const double model = kv::t200_thrust(u, sheet.volts) / kKgf;
      const double e = (model - data) / std::max(std::abs(data), 0.3);
      INFO(sheet.volts << " V, " << 1100 + 4 * k << " us: data " << data << " kgf, fit " << model);
      CHECK(std::abs(e) <= 0.10);
      ++checked;
      if (data == 0.0) continue;
      const int d = data > 0 ? 0 : 1;
      max_rel[d] = std::max(max_rel[d], std::abs(e));
      sum_sq[d] += e * e;
      ++n[d];
    }
  }
  CHECK(checked == 5 * 201);
  // The fit's own numbers over the non-zero readings (t200.hpp states them over all points).
  INFO("forward: max " << max_rel[0] << ", RMS " << std::sqrt(sum_sq[0] / n[0]) << "; reverse: max "
                       << max_rel[1] << ", RMS " << std::sqrt(sum_sq[1] / n[1]));
  CHECK(max_rel[0] < 0.072);
  CHECK(max_rel[1] < 0.076);
  CHECK(std::sqrt(sum_sq[0] / n[0]) < 0.025);
  CHECK(std::sqrt(sum_sq[1] / n[1]) < 0.023);
  // 14 V: only the full-throttle values were reachable (4.53 kgf forward, 3.52 kgf reverse).
  CHECK(kv::t200_max_thrust(14.0) / kKgf == Approx(4.53).epsilon(0.02));
  CHECK(kv::t200_max_reverse_thrust(14.0) / kKgf == Approx(3.52).epsilon(0.02));
}

TEST_CASE("T200: supply current within 10 % of every data point (below 1 A: within 0.1 A)",
          "[vehicle][t200]") {
  for (const Sheet& sheet : kSheets) {
    for (int k = 0; k < 201; ++k) {
      const double u = command_of_row(k);
      const double data = sheet.current[k] / 100.0;
      const double model = kv::t200_current(u, sheet.volts);
      INFO(sheet.volts << " V, " << 1100 + 4 * k << " us: data " << data << " A, fit " << model);
      CHECK(model >= 0.0);
      CHECK(std::abs(model - data) <= 0.10 * std::max(data, 1.0));
    }
  }
  // Blue Robotics' technical details: about 24 A at full throttle at 16 V.
  CHECK(kv::t200_current(1.0, 16.0) == Approx(24).epsilon(0.03));
  CHECK(kv::t200_current(-1.0, 16.0) == Approx(24).epsilon(0.03));
}

TEST_CASE("T200: forward/reverse asymmetry and voltage scaling as in the data", "[vehicle][t200]") {
  // The technical details: 5.25 / 4.1 kgf at 16 V, 3.71 / 2.92 kgf at 12 V.
  CHECK(kv::t200_max_thrust(16.0) / kKgf == Approx(5.25).epsilon(0.01));
  CHECK(kv::t200_max_reverse_thrust(16.0) / kKgf == Approx(4.07).epsilon(0.01));
  CHECK(kv::t200_max_thrust(12.0) / kKgf == Approx(3.71).epsilon(0.01));
  CHECK(kv::t200_max_reverse_thrust(12.0) / kKgf == Approx(2.92).epsilon(0.01));
  CHECK(kv::t200_thrust(-1.0, 16.0) == -kv::t200_max_reverse_thrust(16.0));
  // The front gives ~30 % more thrust than the back: forward/reverse 1.27 (10 V) to 1.33 (20 V).
  for (const Sheet& sheet : kSheets) {
    const double data = -double(sheet.thrust[200]) / sheet.thrust[0];
    const double fit = kv::t200_max_thrust(sheet.volts) / kv::t200_max_reverse_thrust(sheet.volts);
    INFO(sheet.volts << " V");
    CHECK(fit == Approx(data).epsilon(0.02));
    CHECK(fit > 1.2);
    CHECK(fit < 1.4);
    // ... and at part command too: the same |u| gives more thrust forward.
    CHECK(kv::t200_thrust(0.5, sheet.volts) > -kv::t200_thrust(-0.5, sheet.volts));
  }
  // Voltage: full throttle 16 V / 12 V = 5.25 / 3.71 = 1.415 forward, 4.07 / 2.92 = 1.394 reverse.
  CHECK(kv::t200_max_thrust(16.0) / kv::t200_max_thrust(12.0) == Approx(5.25 / 3.71).epsilon(0.02));
  CHECK(kv::t200_max_reverse_thrust(16.0) / kv::t200_max_reverse_thrust(12.0) ==
        Approx(4.07 / 2.92).epsilon(0.02));
  // More voltage, more thrust and current at full command (at part command the data need not
  // rise: 1660 µs gives 1.32 kgf at 18 V and 1.28 kgf at 20 V); none at 0 V; continuous at 10 V
  // where the data end and the (V/10)² extrapolation begins.
  double previous[4] = {0, 0, 0, 0};
  for (double v = 0.5; v <= 20.0; v += 0.5) {
    const double now[4] = {kv::t200_max_thrust(v), kv::t200_max_reverse_thrust(v),
                           kv::t200_current(1.0, v), kv::t200_current(-1.0, v)};
    for (int k = 0; k < 4; ++k) {
      CHECK(now[k] > previous[k]);
      previous[k] = now[k];
    }
  }
  for (double u = -1.0; u <= 1.0; u += 0.05) {
    if (std::abs(u) <= 0.09) continue;
    CHECK(kv::t200_thrust(u, 0.0) == 0.0);
    CHECK(kv::t200_current(u, 0.0) == 0.0);
    CHECK(kv::t200_thrust(u, 10.0 - 1e-9) == Approx(kv::t200_thrust(u, 10.0)).epsilon(1e-8));
    CHECK(kv::t200_thrust(u, 5.0) == Approx(0.25 * kv::t200_thrust(u, 10.0)).epsilon(1e-12));
  }
}

TEST_CASE("T200: the ESC dead band gives no thrust and no current", "[vehicle][t200]") {
  for (double v : {0.0, 7.0, 10.0, 14.8, 16.0, 20.0}) {
    for (double u = -0.06; u <= 0.06; u += 0.005) {
      CHECK(kv::t200_thrust(u, v) == 0.0);
      CHECK(kv::t200_thrust_slope(u, v) == 0.0);
      CHECK(kv::t200_current(u, v) == 0.0);
    }
  }
  // PWM 1480-1520 µs read zero at every voltage in the data; so does the fit.
  for (const Sheet& sheet : kSheets)
    for (int k = 95; k <= 105; ++k) {
      CHECK(sheet.thrust[k] == 0);
      CHECK(kv::t200_thrust(command_of_row(k), sheet.volts) == 0.0);
    }
  // The dead band widens as the voltage falls (±40 µs read zero at 10 V, ±28 µs at 16 V).
  CHECK(kv::t200_dead_band(16.0) == Approx(0.07));
  CHECK(kv::t200_dead_band(10.0) > kv::t200_dead_band(16.0));
  CHECK(kv::t200_dead_band(20.0) < kv::t200_dead_band(16.0));
  CHECK(kv::t200_dead_band(5.0) == kv::t200_dead_band(10.0));
  // Just outside it thrust starts, in the right direction.
  CHECK(kv::t200_thrust(0.075, 16.0) > 0.0);
  CHECK(kv::t200_thrust(-0.075, 16.0) < 0.0);
  CHECK(kv::t200_current(0.075, 16.0) >= 0.0);
  CHECK(kv::t200_command(0.0, 16.0) == 0.0);
}

TEST_CASE("T200: monotone in the command, so the inverse is unique; round trip at many voltages",
          "[vehicle][t200]") {
  for (double v : {0.3, 5.0, 10.0, 12.0, 13.2, 14.8, 16.0, 16.8, 18.0, 20.0}) {
    INFO(v << " V");
    double previous = 0.0;
    for (double u = kv::t200_dead_band(v) + 1e-4; u <= 1.0; u += 0.0005) {
      const double f = kv::t200_thrust(u, v);
      CHECK(f > previous);
      CHECK(kv::t200_thrust_slope(u, v) > 0.0);
      CHECK(-kv::t200_thrust(-u, v) > 0.0);
      CHECK(kv::t200_thrust_slope(-u, v) > 0.0);
      previous = f;
    }
    const double up = kv::t200_max_thrust(v), down = kv::t200_max_reverse_thrust(v);
    for (double x = -0.999; x <= 0.999; x += 0.037) {
      const double force = x > 0 ? x * up : x * down;
      const double u = kv::t200_command(force, v);
      CHECK(std::abs(u) <= 1.0);
      CHECK(kv::t200_thrust(u, v) == Approx(force).margin(1e-9 * (1 + up)));
    }
    // Saturation at the largest thrust that way.
    CHECK(kv::t200_command(up * 1.5 + 1, v) == 1.0);
    CHECK(kv::t200_command(-down * 1.5 - 1, v) == -1.0);
  }
  // The slope is the derivative of the thrust (central differences), both branches, and in V
  // the thrust is smooth on the data range.
  for (double v : {8.0, 12.0, 16.0, 19.0}) {
    for (double u = -0.95; u <= 0.95; u += 0.05) {
      if (std::abs(u) < 0.1) continue;
      const double h = 1e-6;
      const double fd = (kv::t200_thrust(u + h, v) - kv::t200_thrust(u - h, v)) / (2 * h);
      CHECK(kv::t200_thrust_slope(u, v) == Approx(fd).epsilon(1e-6));
    }
  }
  // The one-argument forms are the nominal voltage's.
  CHECK(kv::t200_thrust(0.4) == kv::t200_thrust(0.4, kv::t200_nominal_voltage));
  CHECK(kv::t200_command(10.0) == kv::t200_command(10.0, kv::t200_nominal_voltage));
}

TEMPLATE_TEST_CASE("T200 in float agrees with double", "[vehicle][t200]", float) {
  using S = TestType;
  for (double u = -1.0; u <= 1.0; u += 0.1) {
    CHECK(double(kv::t200_thrust(S(u), S(14.8))) ==
          Approx(kv::t200_thrust(u, 14.8)).epsilon(1e-5).margin(1e-5));
    CHECK(double(kv::t200_current(S(u), S(14.8))) ==
          Approx(kv::t200_current(u, 14.8)).epsilon(1e-5).margin(1e-5));
  }
  CHECK(double(kv::t200_command(S(20), S(14.8))) ==
        Approx(kv::t200_command(20.0, 14.8)).epsilon(1e-5));
}

TEST_CASE("T200: bad input throws", "[vehicle][t200]") {
  const double nan = std::nan(""), inf = INFINITY;
  CHECK_THROWS_WITH(kv::t200_thrust(nan, 16.0), Catch::Contains("thruster command"));
  CHECK_THROWS_WITH(kv::t200_thrust(inf, 16.0), Catch::Contains("thruster command"));
  CHECK_THROWS_WITH(kv::t200_current(nan, 16.0), Catch::Contains("thruster command"));
  CHECK_THROWS_WITH(kv::t200_command(nan, 16.0), Catch::Contains("thruster force"));
  CHECK_THROWS_WITH(kv::t200_thrust(0.5, nan), Catch::Contains("voltage"));
  CHECK_THROWS_WITH(kv::t200_thrust(0.5, -0.1), Catch::Contains("voltage"));
  CHECK_THROWS_WITH(kv::t200_thrust(0.5, 20.5), Catch::Contains("voltage"));
  CHECK_THROWS_WITH(kv::t200_current(0.5, 25.0), Catch::Contains("voltage"));
  CHECK_THROWS_WITH(kv::t200_command(10.0, inf), Catch::Contains("voltage"));
  CHECK_THROWS_WITH(kv::t200_max_thrust(21.0), Catch::Contains("voltage"));
  CHECK_THROWS_AS(kv::t200_thrust_slope(0.5, nan), kelp::invalid_argument);
  // Commands beyond ±1 saturate, they are not errors.
  CHECK(kv::t200_thrust(3.0, 16.0) == kv::t200_thrust(1.0, 16.0));
  CHECK(kv::t200_thrust(-3.0, 16.0) == kv::t200_thrust(-1.0, 16.0));
}

TEST_CASE("chain: a thruster facing backwards gives the reverse branch along its direction",
          "[vehicle][t200][thrusters]") {
  const auto rov = kv::bluerov2_heavy<double>();
  REQUIRE(rov.thruster_facing.size() == 8);
  CHECK(rov.thruster_facing.isOnes());
  CHECK(kv::blueboat<double>().thruster_facing.isOnes());
  const kv::ThrusterAllocationd alloc(rov.thruster_positions, rov.thruster_directions);
  Eigen::VectorXd facing = Eigen::VectorXd::Ones(8);
  facing(0) = -1;
  facing(5) = -1;
  kv::ThrusterChaind chain(alloc, kv::t200_model, rov.pwm, facing);
  const kv::ThrusterChaind plain(alloc, kv::t200_model, rov.pwm);
  CHECK(chain.voltage() == kv::t200_nominal_voltage);
  for (double u : {-1.0, -0.5, 0.3, 1.0}) {
    // Facing −1: +u gives the reverse branch's magnitude along d (and vice versa).
    CHECK(chain.thrust_of_command(0, u) == -kv::t200_thrust(-u, 16.0));
    CHECK(chain.thrust_of_command(1, u) == kv::t200_thrust(u, 16.0));
    CHECK(plain.thrust_of_command(0, u) == kv::t200_thrust(u, 16.0));
  }
  CHECK(chain.thrust_of_command(0, 1.0) == Approx(kv::t200_max_reverse_thrust(16.0)));
  CHECK(chain.max_positive_thrust(0) == Approx(kv::t200_max_reverse_thrust(16.0)));
  CHECK(chain.max_negative_thrust(0) == Approx(kv::t200_max_thrust(16.0)));
  CHECK(chain.max_positive_thrust(1) == Approx(kv::t200_max_thrust(16.0)));
  // PWM all the way: 1900 µs on thruster 1 (facing −1) pushes along d with the weak side.
  double c = 0;
  CHECK(chain.thrust_of_pwm(0, 1900.0, &c) == Approx(kv::t200_max_reverse_thrust(16.0)));
  CHECK(c == 1.0);
  // The inverse respects the facing: desired force → command → the same force, saturated at
  // the limit that way.
  Eigen::VectorXd want(8), cmd(8), got(8);
  want << 30, -30, 45, -45, 10, 30, -50, 0;
  chain.commands_for(want, cmd, got);
  CHECK(cmd(0) > 0);
  CHECK(got(0) == Approx(30));
  CHECK(got(1) == Approx(-30));
  CHECK(got(2) == Approx(45));
  CHECK(got(3) == Approx(-kv::t200_max_reverse_thrust(16.0)));  // saturated: reverse branch
  CHECK(got(5) == Approx(30));
  CHECK(got(6) == Approx(-kv::t200_max_reverse_thrust(16.0)));
  CHECK(cmd(7) == 0.0);
  // Facing −1 at 45 N saturates (its positive side is the 39.8 N reverse branch).
  want(0) = 45;
  chain.commands_for(want, cmd, got);
  CHECK(cmd(0) == 1.0);
  CHECK(got(0) == Approx(kv::t200_max_reverse_thrust(16.0)));
  // Bad facings are refused.
  Eigen::VectorXd bad = Eigen::VectorXd::Ones(8);
  bad(2) = 0.5;
  CHECK_THROWS_WITH(kv::ThrusterChaind(alloc, kv::t200_model, rov.pwm, bad),
                    Catch::Contains("thruster_facing"));
  CHECK_THROWS_WITH(kv::ThrusterChaind(alloc, kv::t200_model, rov.pwm, Eigen::VectorXd::Ones(3)),
                    Catch::Contains("thruster_facing"));
}

TEST_CASE("chain: the supply voltage scales every thrust and the inverse uses it",
          "[vehicle][t200][thrusters]") {
  const auto rov = kv::bluerov2_heavy<double>();
  const kv::ThrusterAllocationd alloc(rov.thruster_positions, rov.thruster_directions);
  kv::ThrusterChaind chain(alloc, kv::t200_model, rov.pwm);
  Eigen::VectorXd pwm(8), u(8), f16(8), f12(8);
  pwm << 1900, 1100, 1700, 1300, 1900, 1900, 1100, 1500;
  const kelp::Vector6<double> w16 = chain.wrench_from_pwm(pwm, u, f16);
  chain.set_voltage(12.0);
  CHECK(chain.voltage() == 12.0);
  const kelp::Vector6<double> w12 = chain.wrench_from_pwm(pwm, u, f12);
  for (int i = 0; i < 8; ++i) CHECK(f12(i) == kv::t200_thrust(u(i), 12.0));
  CHECK(w12.norm() < 0.8 * w16.norm());
  CHECK(chain.max_positive_thrust(0) == Approx(kv::t200_max_thrust(12.0)));
  Eigen::VectorXd want(8), cmd(8), got(8);
  want.setConstant(30.0);
  chain.commands_for(want, cmd, got);
  for (int i = 0; i < 8; ++i) CHECK(cmd(i) == kv::t200_command(30.0, 12.0));
  // A bad voltage is refused and leaves the chain as it was.
  CHECK_THROWS_WITH(chain.set_voltage(25.0), Catch::Contains("voltage"));
  CHECK_THROWS_AS(chain.set_voltage(std::nan("")), kelp::invalid_argument);
  CHECK(chain.voltage() == 12.0);
  CHECK(chain.max_positive_thrust(0) == Approx(kv::t200_max_thrust(12.0)));
  // The von Benzon polynomial is still there for comparison: symmetric, no voltage.
  const kv::ThrusterChaind old(alloc, kv::von_benzon_t200_model, rov.pwm);
  CHECK(old.thrust_of_command(0, 1.0) == Approx(30.4));
  CHECK(old.thrust_of_command(0, -1.0) == Approx(-30.4));
  CHECK(old.max_positive_thrust(0) == kv::von_benzon_t200_max_thrust);
}

TEST_CASE("chain: the datasheet is read at the ESC's pulse width, whatever the PWM mapping",
          "[vehicle][t200][thrusters]") {
  // The BlueBoat's outputs span 1000–2000 µs; the Basic ESC is full at 1100 / 1900 µs. The same
  // pulse width gives the same thrust as on the ROV's 1100–1900 µs mapping, and anything beyond
  // 1900 µs is full thrust.
  const auto boat = kv::blueboat<double>();
  const auto rov = kv::bluerov2_heavy<double>();
  const kv::ThrusterChaind b(
      kv::ThrusterAllocationd(boat.thruster_positions, boat.thruster_directions), kv::t200_model,
      boat.pwm, boat.thruster_facing);
  const kv::ThrusterChaind r(
      kv::ThrusterAllocationd(rov.thruster_positions, rov.thruster_directions), kv::t200_model,
      rov.pwm, rov.thruster_facing);
  for (double pwm = 1100; pwm <= 1900; pwm += 20)
    CHECK(b.thrust_of_pwm(0, pwm) == Approx(r.thrust_of_pwm(0, pwm)).margin(1e-12));
  CHECK(b.thrust_of_pwm(0, 2000) == Approx(kv::t200_max_thrust(16.0)));
  CHECK(b.thrust_of_pwm(1, 1000) == Approx(-kv::t200_max_reverse_thrust(16.0)));
  // The inverse answers in the chain's own command: 0.8 (1900 µs) already gives full thrust.
  Eigen::Vector2d want(30, 100), cmd, got;
  b.commands_for(want, cmd, got);
  CHECK(got(0) == Approx(30));
  CHECK(kv::pwm_from_command(cmd(0), boat.pwm) ==
        Approx(kv::pwm_from_command(kv::t200_command(30.0, 16.0), rov.pwm)));
  CHECK(cmd(1) == Approx(0.8));
  CHECK(got(1) == Approx(kv::t200_max_thrust(16.0)));
  // A polynomial model keeps the chain's command as it is (its u is the normalised command).
  const kv::ThrusterChaind p(
      kv::ThrusterAllocationd(boat.thruster_positions, boat.thruster_directions),
      kv::von_benzon_t200_model, boat.pwm);
  CHECK(p.thrust_of_pwm(0, 1900) == Approx(kv::thrust(kv::von_benzon_t200_model, 0.8)));
}
