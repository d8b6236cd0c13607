// kelp_sitl::mavlink: a small MAVLink v2 codec for the messages kelp-mission uses.
//   crc.hpp       CRC-16/MCRF4XX ("X.25") with CRC_EXTRA
//   wire.hpp      field types, little-endian encode/decode, lengths and CRC_EXTRA from field lists
//   messages.hpp  the message structs (ArduPilot's minimal.xml / common.xml)
//   frame.hpp     v2 framing with truncation, Sender (sequence numbers), Parser (byte stream)
//   enums.hpp     enum values, ArduSub / Rover mode numbers, names for printing
#pragma once

#include "crc.hpp"
#include "enums.hpp"
#include "frame.hpp"
#include "messages.hpp"
#include "wire.hpp"
