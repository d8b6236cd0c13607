// kelp-mission's CSV logs: one file per message type in the --log directory, one row per
// message received from either vehicle, with a `vehicle` column (sub or boat):
//   attitude.csv             t_s,vehicle,time_boot_ms,roll,pitch,yaw,rollspeed,pitchspeed,yawspeed
//   local_position_ned.csv   t_s,vehicle,time_boot_ms,x,y,z,vx,vy,vz
//   global_position_int.csv  t_s,vehicle,time_boot_ms,lat,lon,alt,relative_alt,vx,vy,vz,hdg
//   statustext.csv           t_s,vehicle,severity,text
//   command_ack.csv          t_s,vehicle,command,result,result_name
// t_s is seconds since kelp-mission started (its own clock); the other columns are the MAVLink
// fields in the message's units (rad, m, m/s, degE7, mm, cm/s, cdeg).
#pragma once

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "mavlink/enums.hpp"
#include "mavlink/messages.hpp"

namespace kelp_sitl::mission {

class CsvLog {
 public:
  // Creates dir (and parents) and the six files with their headers.
  explicit CsvLog(const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    open(attitude_, dir / "attitude.csv",
         "t_s,vehicle,time_boot_ms,roll,pitch,yaw,rollspeed,pitchspeed,yawspeed");
    open(local_, dir / "local_position_ned.csv", "t_s,vehicle,time_boot_ms,x,y,z,vx,vy,vz");
    open(global_, dir / "global_position_int.csv",
         "t_s,vehicle,time_boot_ms,lat,lon,alt,relative_alt,vx,vy,vz,hdg");
    open(text_, dir / "statustext.csv", "t_s,vehicle,severity,text");
    open(ack_, dir / "command_ack.csv", "t_s,vehicle,command,result,result_name");
    open(sys_status_, dir / "sys_status.csv",
         "t_s,vehicle,voltage_battery_V,current_battery_A,battery_remaining_pct");
  }

  void write(double t, const std::string& v, const mavlink::Attitude& m) {
    attitude_ << t << ',' << v << ',' << m.time_boot_ms << ',' << m.roll << ',' << m.pitch << ','
              << m.yaw << ',' << m.rollspeed << ',' << m.pitchspeed << ',' << m.yawspeed << '\n';
  }
  void write(double t, const std::string& v, const mavlink::LocalPositionNed& m) {
    local_ << t << ',' << v << ',' << m.time_boot_ms << ',' << m.x << ',' << m.y << ',' << m.z
           << ',' << m.vx << ',' << m.vy << ',' << m.vz << '\n';
  }
  void write(double t, const std::string& v, const mavlink::GlobalPositionInt& m) {
    global_ << t << ',' << v << ',' << m.time_boot_ms << ',' << m.lat << ',' << m.lon << ','
            << m.alt << ',' << m.relative_alt << ',' << m.vx << ',' << m.vy << ',' << m.vz << ','
            << m.hdg << '\n';
  }
  void write(double t, const std::string& v, const mavlink::Statustext& m) {
    std::string text = mavlink::to_string(m.text);
    for (char& c : text)
      if (c == '"') c = '\'';
    text_ << t << ',' << v << ',' << mavlink::severity_name(m.severity) << ",\"" << text << "\"\n";
  }
  void write(double t, const std::string& v, const mavlink::CommandAck& m) {
    ack_ << t << ',' << v << ',' << m.command << ',' << static_cast<int>(m.result) << ','
         << mavlink::result_name(m.result) << '\n';
  }

  // The battery as the autopilot reports it (SYS_STATUS: mV, cA, %; -1 = unknown).
  void write(double t, const std::string& v, const mavlink::SysStatus& m) {
    sys_status_ << t << ',' << v << ',' << m.voltage_battery / 1000.0 << ','
                << m.current_battery / 100.0 << ',' << static_cast<int>(m.battery_remaining)
                << '\n';
  }

  void flush() {
    for (std::ofstream* f : {&attitude_, &local_, &global_, &text_, &ack_, &sys_status_})
      f->flush();
  }

 private:
  static void open(std::ofstream& f, const std::filesystem::path& path, const char* header) {
    f.open(path);
    if (!f) throw std::runtime_error("cannot write " + path.string());
    f.precision(9);
    f << header << '\n';
  }

  std::ofstream attitude_, local_, global_, text_, ack_, sys_status_;
};

}  // namespace kelp_sitl::mission
