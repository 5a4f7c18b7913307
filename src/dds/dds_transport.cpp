#include "dds/dds_transport.hpp"

#include <dds/ddsi/ddsi_serdata.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <utility>

#include "dds/parameter_wire.hpp"
#include "dds/type_hash.hpp"

namespace quadcosim::dds {

std::string dds_topic_name(const std::string& ros_topic) { return "rt" + ros_topic; }

DdsTransport::DdsTransport(const RosEnvironment& env) : participant_(env) {
  waitset_ = check(dds_create_waitset(participant_.handle()), "dds_create_waitset");
  // Cyclone packs a writer's writes until it is flushed only by a setting of the whole domain
  // (Internal/WriteBatch), which reaches the writers made after it (this transport's; the domain
  // exists now): every write site of quadcosim flushes at once (dds::write_now), except a
  // transport's held sends.
  dds_write_set_batch(true);
}

bool DdsTransport::clock_is_read() const {
  const auto it = writers_.find("/clock");
  if (it == writers_.end()) return false;
  for (const dds_entity_t w : it->second) {
    dds_publication_matched_status_t st{};
    if (dds_get_publication_matched_status(w, &st) == DDS_RETCODE_OK && st.current_count > 0) return true;
  }
  return false;
}

void DdsTransport::hold_sends(bool on) {
  // A node on ROS time (a /clock reader) may step at a /clock sample and read the newest of the
  // others: packing would reorder the topics it sees (/clock of the next tick before the samples
  // of this one), so with a /clock reader every write goes out at once, in publication order.
  holding_ = on && !clock_is_read();
  if (holding_) return;
  for (const dds_entity_t w : held_writers_) dds_write_flush(w);
  held_writers_.clear();
}

DdsTransport::~DdsTransport() {
  // Entities go with the participant (Participant's destructor), listeners with their readers.
}

QosProfile DdsTransport::qos_for(const std::string& ros_topic) const {
  const auto it = qos_.find(ros_topic);
  return it == qos_.end() ? QosProfile::for_topic(ros_topic) : it->second;
}

dds_entity_t DdsTransport::topic_for(const std::string& ros_topic, const sim::TopicType& type, const TypeOps*& ops) {
  ops = type_ops(type.cpp_type);
  if (!ops) throw DdsError("no DDS mapping for message type " + std::string(type.ros_type));
  auto it = topics_.find(ros_topic);
  if (it != topics_.end()) return it->second;
  const std::string name = dds_topic_name(ros_topic);
  const dds_entity_t t = check(dds_create_topic(participant_.handle(), ops->descriptor, name.c_str(), nullptr, nullptr),
                               ("dds_create_topic " + name).c_str());
  topics_.emplace(ros_topic, t);
  return t;
}

dds_entity_t DdsTransport::create_endpoint(const std::string& ros_topic, const sim::TopicType& type, bool writer,
                                           const TypeOps*& ops, const sim::QosChoice& qos_given) {
  const dds_entity_t topic = topic_for(ros_topic, type, ops);
  const QosProfile p = qos_given ? *qos_given : qos_for(ros_topic);
  const Qos qos(ros_qos(p.depth, p.reliable, p.transient_local));
  set_endpoint_user_data(qos.get(), ops->descriptor->m_typename, user_data_keys_);
  const dds_entity_t e = writer ? dds_create_writer(participant_.handle(), topic, qos.get(), nullptr)
                                : dds_create_reader(participant_.handle(), topic, qos.get(), nullptr);
  check(e, ((writer ? "dds_create_writer " : "dds_create_reader ") + ros_topic).c_str());
  // Matching changes wake spin_once, so waits for a peer need no polling.
  const std::uint32_t matched = writer ? DDS_PUBLICATION_MATCHED_STATUS : DDS_SUBSCRIPTION_MATCHED_STATUS;
  check(dds_set_status_mask(e, matched), "dds_set_status_mask");
  attach(e, -1 - static_cast<dds_attach_t>(matched_.size()));
  matched_.push_back({e, matched});
  return e;
}

void DdsTransport::attach(dds_entity_t e, dds_attach_t arg) {
  check(dds_waitset_attach(waitset_, e, arg), "dds_waitset_attach");
  triggered_.push_back(0);
}

std::function<void(const void*)> DdsTransport::make_sink(const std::string& ros_topic, const sim::TopicType& type,
                                                         const sim::QosChoice& qos) {
  const TypeOps* ops = nullptr;
  const dds_entity_t writer = create_endpoint(ros_topic, type, true, ops, qos);
  writers_[ros_topic].push_back(writer);
  return [this, writer, ops, ros_topic](const void* message) {
    // The error's text is formed only on an error: a write is on every tick's path.
    if (const dds_return_t rc = ops->write(writer, message); rc < 0) check(rc, ("dds_write " + ros_topic).c_str());
    if (!holding_) {
      dds_write_flush(writer);
    } else if (std::find(held_writers_.begin(), held_writers_.end(), writer) == held_writers_.end()) {
      held_writers_.push_back(writer);
    }
  };
}

void DdsTransport::add_subscription(const std::string& ros_topic, const sim::TopicType& type, const sim::QosChoice& qos,
                                    std::function<void(const void*)> deliver) {
  const TypeOps* ops = nullptr;
  const dds_entity_t reader = create_endpoint(ros_topic, type, false, ops, qos);
  add_reader(reader, ros_topic, ops, std::move(deliver));
}

void DdsTransport::add_subscription_with_sender(const std::string& ros_topic, const sim::TopicType& type,
                                                const sim::QosChoice& qos,
                                                std::function<void(const void*, sim::SenderId)> deliver) {
  const TypeOps* ops = nullptr;
  const dds_entity_t reader = create_endpoint(ros_topic, type, false, ops, qos);
  // The reader's entry is made by add_reader at this index (entries keep their addresses).
  add_reader(reader, ros_topic, ops,
             [this, index = readers_.size(), d = std::move(deliver)](const void* m) { d(m, readers_[index]->sender); });
}

void DdsTransport::add_tap(const std::string& ros_topic, const sim::TopicType& type, const sim::QosChoice& qos,
                           std::function<void(const void*, sim::SenderId, sim::WireBytes)> deliver) {
  const TypeOps* ops = nullptr;
  const dds_entity_t reader = create_endpoint(ros_topic, type, false, ops, qos);
  add_reader(
      reader, ros_topic, ops,
      [this, index = readers_.size(), d = std::move(deliver)](const void* m) {
        const Reader& r = *readers_[index];
        d(m, r.sender, r.wire);
      },
      true);
}

std::optional<DdsTransport::SenderInfo> DdsTransport::sender_info(const std::string& ros_topic,
                                                                  sim::SenderId sender) const {
  for (const auto& r : readers_) {
    if (r->topic != ros_topic) continue;
    dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(r->reader, sender);
    if (e == nullptr) continue;
    SenderInfo info;
    std::copy(std::begin(e->participant_key.v), std::end(e->participant_key.v), info.participant.begin());
    info.pair_token = wire::user_data_value(e->qos, kPairTokenKey);
    dds_builtintopic_free_endpoint(e);
    return info;
  }
  return std::nullopt;
}

std::vector<sim::SenderId> DdsTransport::matched_senders(const std::string& ros_topic) const {
  std::vector<sim::SenderId> out;
  for (const auto& r : readers_) {
    if (r->topic != ros_topic) continue;
    dds_instance_handle_t handles[64];
    const dds_return_t n = dds_get_matched_publications(r->reader, handles, 64);
    for (dds_return_t i = 0; i < std::min<dds_return_t>(n, 64); ++i) out.push_back(handles[i]);
  }
  return out;
}

std::vector<std::array<std::uint8_t, 16>> DdsTransport::matched_reader_participants(
    const std::string& ros_topic) const {
  std::vector<std::array<std::uint8_t, 16>> out;
  const auto it = writers_.find(ros_topic);
  if (it == writers_.end()) return out;
  for (dds_entity_t w : it->second) {
    dds_instance_handle_t handles[64];
    const dds_return_t n = dds_get_matched_subscriptions(w, handles, 64);
    for (dds_return_t i = 0; i < std::min<dds_return_t>(n, 64); ++i) {
      dds_builtintopic_endpoint_t* e = dds_get_matched_subscription_data(w, handles[i]);
      if (e == nullptr) continue;
      std::array<std::uint8_t, 16> p{};
      std::copy(std::begin(e->participant_key.v), std::end(e->participant_key.v), p.begin());
      out.push_back(p);
      dds_builtintopic_free_endpoint(e);
    }
  }
  return out;
}

void DdsTransport::subscribe_raw(dds_entity_t reader, std::string label, std::function<void(const void*)> deliver) {
  add_reader(reader, std::move(label), nullptr, std::move(deliver));
}

void DdsTransport::subscribe_raw_with_sender(dds_entity_t reader, std::string label,
                                             std::function<void(const void*, sim::SenderId)> deliver) {
  add_reader(reader, std::move(label), nullptr,
             [this, index = readers_.size(), d = std::move(deliver)](const void* m) { d(m, readers_[index]->sender); });
}

void DdsTransport::add_reader(dds_entity_t reader, std::string topic, const TypeOps* ops,
                              std::function<void(const void*)> deliver, bool tap) {
  auto r = std::make_unique<Reader>();
  r->owner = this;
  r->index = readers_.size();
  r->topic = std::move(topic);
  r->reader = reader;
  r->condition = check(dds_create_readcondition(reader, DDS_ANY_STATE), "dds_create_readcondition");
  r->ops = ops;
  r->deliver = std::move(deliver);
  r->tap = tap;
  Reader& added = *r;
  readers_.push_back(std::move(r));
  if (arrival_sink_) {
    // Announced by the listener from the start (none on the waitset); what came before the
    // listener was set is announced now.
    listen(added, true);
    arrival_sink_(added.index);
  } else {
    attach(added.condition, static_cast<dds_attach_t>(added.index));
  }
}

void DdsTransport::listen(Reader& r, bool on) {
  if (on) {
    dds_listener_t* l = dds_create_listener(&r);
    dds_lset_data_available(l, &DdsTransport::on_data_available);
    const dds_return_t rc = dds_set_listener(r.reader, l);
    dds_delete_listener(l);
    check(rc, ("dds_set_listener " + r.topic).c_str());
  } else {
    check(dds_set_listener(r.reader, nullptr), ("dds_set_listener " + r.topic).c_str());  // waits for a callback
  }
}

void DdsTransport::on_data_available(dds_entity_t, void* arg) {
  const Reader& r = *static_cast<const Reader*>(arg);
  r.owner->arrival_sink_(r.index);
}

void DdsTransport::set_arrival_sink(std::function<void(std::size_t)> sink) {
  if (!sink && !arrival_sink_) return;
  if (sink && arrival_sink_) throw std::logic_error("DdsTransport: a second ArrivalExecutor on one transport");
  const bool on = static_cast<bool>(sink);
  if (on) arrival_sink_ = std::move(sink);  // before the first listener can call it
  for (auto& r : readers_) {
    if (on) {
      if (dds_waitset_detach(waitset_, r->condition) == DDS_RETCODE_OK) triggered_.pop_back();
      listen(*r, true);
    } else {
      listen(*r, false);  // waits for a listener call in progress
      attach(r->condition, static_cast<dds_attach_t>(r->index));
    }
  }
  if (!on) arrival_sink_ = nullptr;
}

void DdsTransport::deliver_serialised(Reader& r, ddsi_serdata* sd) {
  // The bytes as the writer serialised them: XCDR1, encapsulation header first. Cyclone pads them to
  // a multiple of 4 and counts the pad in the options' low bits; without both they are io::to_cdr's.
  const std::uint32_t size = ddsi_serdata_size(sd);
  r.wire_buffer.resize(size);
  ddsi_serdata_to_ser(sd, 0, size, r.wire_buffer.data());
  std::size_t n = size;
  if (size >= 4) {
    n -= std::min<std::size_t>(r.wire_buffer[3] & 0x3u, size - 4);
    r.wire_buffer[3] = static_cast<std::uint8_t>(r.wire_buffer[3] & ~0x3u);
  }
  r.wire = sim::WireBytes(r.wire_buffer.data(), n);
  // The message, decoded from the same bytes (the C sample's contents freed after the delivery).
  alignas(std::max_align_t) unsigned char sample[1024] = {};
  if (r.ops->descriptor->m_size > sizeof sample) throw DdsError("dds tap " + r.topic + ": sample too large");
  if (!ddsi_serdata_to_sample(sd, sample, nullptr, nullptr)) throw DdsError("dds tap " + r.topic + ": undecodable");
  try {
    r.ops->deliver(sample, r.deliver);
  } catch (...) {
    dds_sample_free(sample, r.ops->descriptor, DDS_FREE_CONTENTS);
    r.wire = {};
    throw;
  }
  dds_sample_free(sample, r.ops->descriptor, DDS_FREE_CONTENTS);
  r.wire = {};
}

int DdsTransport::deliver_taken(Reader& r, void* const* samples, ddsi_serdata* const* serdata,
                                const dds_sample_info_t* infos, int n) {
  int delivered = 0;
  for (int i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    r.sender = infos[i].publication_handle;
    if (r.tap) {
      deliver_serialised(r, serdata[i]);
    } else if (r.ops != nullptr) {
      r.ops->deliver(samples[i], r.deliver);
    } else {
      r.deliver(samples[i]);
    }
    ++delivered;
  }
  return delivered;
}

dds_return_t DdsTransport::take_batch(Reader& r, void** samples, ddsi_serdata** serdata, dds_sample_info_t* infos) {
  const dds_return_t n = r.tap ? dds_takecdr(r.reader, serdata, Held::kBatch, infos, DDS_ANY_STATE)
                               : dds_take(r.reader, samples, infos, Held::kBatch, Held::kBatch);
  if (n < 0) check(n, ((r.tap ? "dds_takecdr " : "dds_take ") + r.topic).c_str());
  return n;
}

void DdsTransport::give_back(const Reader& r, void** samples, ddsi_serdata** serdata, int n) {
  if (n <= 0) return;
  if (r.tap) {
    for (int i = 0; i < n; ++i) ddsi_serdata_unref(serdata[i]);
  } else {
    dds_return_loan(r.reader, samples, n);
  }
}

int DdsTransport::drain(Reader& r) {
  constexpr int kBatch = Held::kBatch;
  int delivered = 0;
  for (;;) {
    void* samples[kBatch] = {nullptr};
    ddsi_serdata* serdata[kBatch] = {nullptr};
    dds_sample_info_t infos[kBatch];
    const dds_return_t n = take_batch(r, samples, serdata, infos);
    if (n == 0) break;
    try {
      delivered += deliver_taken(r, samples, serdata, infos, n);
    } catch (...) {
      give_back(r, samples, serdata, n);  // the loan goes back whatever a delivery throws
      throw;
    }
    give_back(r, samples, serdata, n);
    if (n < kBatch) break;
  }
  return delivered;
}

void DdsTransport::hold(std::size_t index, std::vector<Held>& into) {
  // Cyclone lends its one buffer to the first take and allocates for the others (given back
  // by dds_return_loan too), so any number may be held at once; a tap holds references.
  Reader& r = *readers_[index];
  for (;;) {
    Held h;
    h.index = index;
    const dds_return_t n = take_batch(r, h.samples, h.serdata, h.infos);
    if (n == 0) break;
    h.n = n;
    into.push_back(h);
    if (n < Held::kBatch) break;
  }
}

int DdsTransport::deliver_held(Held& held) {
  Reader& r = *readers_[held.index];
  try {
    const int delivered = deliver_taken(r, held.samples, held.serdata, held.infos, held.n);
    drop_held(held);
    return delivered;
  } catch (...) {
    drop_held(held);
    throw;
  }
}

void DdsTransport::drop_held(Held& held) {
  give_back(*readers_[held.index], held.samples, held.serdata, held.n);
  held.n = 0;
}

int DdsTransport::spin_once(std::int64_t timeout_ns) {
  if (arrival_sink_) {
    throw std::logic_error(
        "DdsTransport::spin_once called while an ArrivalExecutor delivers on arrival "
        "(wait through the executor)");
  }
  if (readers_.empty() && writers_.empty() && extra_.empty()) return 0;
  return serve_wait(wait_waitset(timeout_ns));
}

dds_return_t DdsTransport::wait_waitset(std::int64_t timeout_ns) {
  return dds_waitset_wait(waitset_, triggered_.data(), triggered_.size(), timeout_ns);
}

int DdsTransport::serve_wait(dds_return_t rc) {
  check(rc, "dds_waitset_wait");
  ready_.clear();
  std::uint32_t status = 0;
  if (static_cast<std::size_t>(rc) <= triggered_.size()) {
    for (dds_return_t i = 0; i < rc; ++i) {
      const dds_attach_t a = triggered_[static_cast<std::size_t>(i)];
      if (a >= 0) {
        ready_.push_back(static_cast<std::size_t>(a));
      } else if (a != kExtra) {  // clear the matched-status trigger (the counts stay readable)
        const Matched& m = matched_[static_cast<std::size_t>(-1 - a)];
        dds_take_status(m.entity, &status, m.status);
      }
    }
    std::sort(ready_.begin(), ready_.end());
  } else {  // more triggered than attached (cannot happen: one slot per attachment); look at all
    for (const Matched& m : matched_) dds_take_status(m.entity, &status, m.status);
    if (!arrival_sink_) {
      for (std::size_t i = 0; i < readers_.size(); ++i) ready_.push_back(i);
    }
  }
  int delivered = 0;
  for (std::size_t i : ready_) delivered += drain(*readers_[i]);
  if (!extra_.empty()) {
    // Copied first (into a kept vector): a callback may add or remove extra work.
    serving_.clear();
    for (const auto& [id, w] : extra_) serving_.push_back(w.serve);
    for (const auto& f : serving_) f();
  }
  return delivered;
}

int DdsTransport::add_extra_work(const std::vector<dds_entity_t>& wake_on, std::function<void()> serve) {
  const int id = next_extra_id_++;
  for (dds_entity_t e : wake_on) attach(e, kExtra);
  extra_[id] = ExtraWork{wake_on, std::move(serve)};
  return id;
}

void DdsTransport::remove_extra_work(int id) {
  const auto it = extra_.find(id);
  if (it == extra_.end()) return;
  for (dds_entity_t e : it->second.wake_on) {
    if (dds_waitset_detach(waitset_, e) == DDS_RETCODE_OK) triggered_.pop_back();
  }
  extra_.erase(it);
}

namespace {
constexpr std::int64_t kSpinSliceNs = 100'000'000;
}  // namespace

bool DdsTransport::spin_until(const std::function<bool()>& done, std::int64_t timeout_ns) {
  using clock = std::chrono::steady_clock;
  const auto deadline = clock::now() + std::chrono::nanoseconds(timeout_ns);
  while (!done()) {
    const auto left = std::chrono::duration_cast<std::chrono::nanoseconds>(deadline - clock::now()).count();
    if (left <= 0) return done();
    // In slices, so a `done` that watches something no DDS event signals (a stop requested by a
    // signal handler) is seen within one slice.
    spin_once(std::min<std::int64_t>(left, kSpinSliceNs));
  }
  return true;
}

int DdsTransport::matched_writers(const std::string& ros_topic) const {
  int n = 0;
  for (const auto& r : readers_) {
    if (r->topic != ros_topic) continue;
    dds_subscription_matched_status_t s;
    if (dds_get_subscription_matched_status(r->reader, &s) >= 0) n += static_cast<int>(s.current_count);
  }
  return n;
}

bool DdsTransport::wait_for_acks(const std::string& ros_topic, std::int64_t timeout_ns) {
  const auto it = writers_.find(ros_topic);
  if (it == writers_.end()) return true;
  for (dds_entity_t w : it->second) {
    if (dds_wait_for_acks(w, timeout_ns) != DDS_RETCODE_OK) return false;
  }
  return true;
}

int DdsTransport::matched_readers(const std::string& ros_topic) const {
  int n = 0;
  const auto it = writers_.find(ros_topic);
  if (it == writers_.end()) return 0;
  for (dds_entity_t w : it->second) {
    dds_publication_matched_status_t s;
    if (dds_get_publication_matched_status(w, &s) >= 0) n += static_cast<int>(s.current_count);
  }
  return n;
}

}  // namespace quadcosim::dds
