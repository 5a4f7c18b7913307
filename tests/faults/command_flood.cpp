// command_flood: publishes rotor speed commands on <ns>/motor_commands as fast as it can, to check
// that a flood from another participant does not starve the plant's loop. Bounded: it stops after
// --count messages or --seconds of wall time, whichever comes first, and prints what it sent.
// --rate R paces it at R messages per second (in bursts every millisecond; 0: as fast as it can).
// Usage: command_flood [--seconds S] [--count N] [--rate R] [--omega W] [--namespace NS]
#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>
#include <thread>

#include "dds/dds_transport.hpp"
#include "sim/messages.hpp"
#include "sim/topics.hpp"

int main(int argc, char** argv) {
  using namespace quadcosim;
  double seconds = 3.0, omega = 4830.0, rate = 0.0;
  long long count = 1'000'000;
  std::string ns = "/drone";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--seconds")
      seconds = std::atof(v.c_str());
    else if (a == "--count")
      count = std::atoll(v.c_str());
    else if (a == "--omega")
      omega = std::atof(v.c_str());
    else if (a == "--rate")
      rate = std::atof(v.c_str());
    else if (a == "--namespace")
      ns = v;
    else {
      std::cerr << "command_flood: unknown option " << a << '\n';
      return 2;
    }
  }
  if (!(seconds > 0.0 && seconds <= 60.0) || count <= 0 || !(rate >= 0.0 && rate <= 1e7)) {
    std::cerr << "command_flood: --seconds in (0, 60], --count > 0, --rate in [0, 1e7]\n";
    return 2;
  }
  dds::DdsTransport transport(dds::read_ros_environment());
  const sim::Topics topics = sim::Topics::for_namespace(ns);
  auto pub = transport.advertise<msg::Float64MultiArray>(topics.motor_commands);
  // Start once a plant listens, so the flood is not spent on nobody.
  if (!transport.spin_until([&] { return transport.matched_readers(topics.motor_commands) > 0; }, 10'000'000'000)) {
    std::cerr << "command_flood: no reader of " << topics.motor_commands << " within 10 s\n";
    return 4;
  }
  msg::Float64MultiArray m;
  m.data = {omega, omega, omega, omega};
  m.dim = {{"", 4, 4}};
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  const auto end = start + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(seconds));
  long long sent = 0;
  while (sent < count && clock::now() < end) {
    if (rate > 0.0) {
      // Due so far at this rate; publish up to it, then sleep a millisecond.
      const double elapsed = std::chrono::duration<double>(clock::now() - start).count();
      const auto due = static_cast<long long>(elapsed * rate);
      if (sent >= due) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
    }
    pub.publish(m);
    ++sent;
  }
  const double wall = std::chrono::duration<double>(clock::now() - start).count();
  std::cout << fmt::format("command_flood: sent {} commands in {:.3f} s ({:.0f} per second)\n", sent, wall,
                           static_cast<double>(sent) / wall);
  return 0;
}
