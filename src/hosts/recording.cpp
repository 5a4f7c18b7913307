#include "hosts/recording.hpp"

#include <memory>
#include <stdexcept>

#include "hosts/foxglove_serving.hpp"

namespace quadcosim::hosts {

io::Recording make_recording(const RecordingOptions& o, sim::Transport* bus) {
  io::Recording rec = io::make_recording(o, bus);
  if (!o.foxglove.listen.empty()) {
    if (!bus) throw std::invalid_argument("make_recording: --foxglove needs the run's bus");
    rec.add(std::make_unique<FoxgloveRecording>(o.foxglove, o.who, o, *bus));
  }
  return rec;
}

}  // namespace quadcosim::hosts
