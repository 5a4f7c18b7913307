// The conversions between a message struct of sim/messages.hpp and the C type idlc generates for it,
// derived from two lists stated elsewhere: the message's fields() (sim/messages.hpp) and the
// instructions idlc generates for the C type (the descriptor's m_ops: per member, in IDL declaration
// order, an ADR instruction with the member's type and byte offset). Walk goes through both in step:
// each field's C++ type must be what its instruction says (bool: boolean; an N-byte integer: N-byte
// integer of the same signedness; double: 8-byte floating point; std::string: unbounded string;
// std::array<E, N>: array of N E; std::vector<E>: sequence of E; a message or a group: a nested
// struct), and both lists must end together. Any difference throws std::logic_error naming the type,
// the field and the instruction, so a field added on one side only is refused before anything is sent.
// Internal to the DDS layer (dds/ros_types.cpp) and its tests.
#pragma once

#include <dds/dds.h>

#include <array>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "sim/messages.hpp"

namespace quadcosim::dds::idl_walk {

// The layout every idlc sequence type (dds_sequence_double, dds_sequence_string, ...) has.
struct CSeq {
  std::uint32_t _maximum;
  std::uint32_t _length;
  void* _buffer;
  bool _release;
};

using msg::IsArray;
using msg::IsVector;

template <class T>
constexpr bool kPrimitive = std::is_arithmetic_v<T>;

// The type code idlc gives a primitive C++ type, and its flags (floating point, signed).
template <class T>
constexpr std::uint32_t primitive_code() {
  if constexpr (std::is_same_v<T, bool>) {
    return DDS_OP_VAL_BLN;
  } else {
    static_assert(sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4 || sizeof(T) == 8);
    return sizeof(T) == 1   ? DDS_OP_VAL_1BY
           : sizeof(T) == 2 ? DDS_OP_VAL_2BY
           : sizeof(T) == 4 ? DDS_OP_VAL_4BY
                            : DDS_OP_VAL_8BY;
  }
}
template <class T>
constexpr std::uint32_t primitive_flags() {
  if constexpr (std::is_floating_point_v<T>) return DDS_OP_FLAG_FP;
  if constexpr (std::is_signed_v<T> && !std::is_same_v<T, bool>) return DDS_OP_FLAG_SGN;
  return 0;
}

// Storage for the C view of sequences of strings or structs while one write runs.
class Arena {
 public:
  void* zeroed(std::size_t n) {
    constexpr std::size_t kAlign = alignof(std::max_align_t);
    const std::size_t at = (used_ + kAlign - 1) / kAlign * kAlign;
    void* p;
    if (at + n <= sizeof inline_) {
      p = inline_ + at;
      used_ = at + n;
    } else {
      heap_.push_back(std::make_unique<unsigned char[]>(n));  // new[]: aligned for any fundamental type
      p = heap_.back().get();
    }
    std::memset(p, 0, n);
    return p;
  }

 private:
  alignas(std::max_align_t) unsigned char inline_[256];
  std::size_t used_ = 0;
  std::vector<std::unique_ptr<unsigned char[]>> heap_;
};

enum class Mode {
  kCheck,  ///< only compare the two lists (no C sample)
  kToC,    ///< C++ message -> C sample; strings and sequence buffers borrow the message's memory
  kFromC,  ///< C sample -> C++ message
};

// Walks one struct: the fields its fields() hands over, against the C struct's instructions from `op`.
// Only kCheck compares; kToC and kFromC trust the instructions, so run kCheck (check_fields) on the
// pair first (dds/ros_types.cpp does, for every type, before it hands out a conversion).
template <Mode kMode>
class Walk {
 public:
  using Byte = std::conditional_t<kMode == Mode::kFromC, const unsigned char, unsigned char>;

  Walk(std::string_view type, const std::uint32_t* op, Byte* c, Arena* arena, const Walk* parent = nullptr,
       std::string_view name = {})
      : type_(type), op_(op), c_(c), arena_(arena), parent_(parent), name_(name) {}

  template <class T>
  void field(std::string_view name, T& v, msg::FieldNote = {}) {
    member(name, v);
  }
  template <class F>
  void group(std::string_view name, std::string_view /*ros_type*/, F&& visit) {
    const std::uint32_t insn = next(name);
    expect(name, DDS_OP_TYPE(insn) == DDS_OP_VAL_EXT && DDS_OP_TYPE_FLAGS(insn) == 0 && DDS_OP_FLAGS(insn) == 0, insn,
           "a nested struct");
    Walk sub(type_, op_ + DDS_OP_ADR_JSR(op_[2]), at(op_[1]), arena_, this, name);
    visit(sub);
    sub.end();
    op_ += DDS_OP_ADR_JMP(op_[2]);
  }

  /// After the last field: the C struct must have no member left.
  void end() const {
    if (kMode == Mode::kCheck && DDS_OP(*op_) != DDS_OP_RTS)
      fail({}, "the IDL type has a member after the last field fields() lists");
  }

 private:
  template <class T>
  void member(std::string_view name, T& v) {
    using U = std::remove_const_t<T>;
    const std::uint32_t insn = next(name);
    const auto type = DDS_OP_TYPE(insn);
    Byte* const c = at(op_[1]);
    if constexpr (kPrimitive<U>) {
      expect(name,
             type == primitive_code<U>() && DDS_OP_FLAGS(insn) == primitive_flags<U>() && DDS_OP_TYPE_FLAGS(insn) == 0,
             insn, "a primitive of the C++ field's size and kind");
      if constexpr (kMode == Mode::kToC) std::memcpy(c, &v, sizeof(U));
      if constexpr (kMode == Mode::kFromC) std::memcpy(&v, c, sizeof(U));
      op_ += 2;
    } else if constexpr (std::is_same_v<U, std::string>) {
      expect(name, type == DDS_OP_VAL_STR && DDS_OP_FLAGS(insn) == 0 && DDS_OP_TYPE_FLAGS(insn) == 0, insn,
             "an unbounded string");
      if constexpr (kMode == Mode::kToC) put_string(c, v);
      if constexpr (kMode == Mode::kFromC) get_string(c, v);
      op_ += 2;
    } else if constexpr (IsArray<U>::value) {
      using E = typename U::value_type;
      static_assert(kPrimitive<E>, "fixed arrays of primitives only");
      expect(name,
             type == DDS_OP_VAL_ARR && DDS_OP_SUBTYPE(insn) == primitive_code<E>() &&
                 DDS_OP_FLAGS(insn) == primitive_flags<E>() && DDS_OP_TYPE_FLAGS(insn) == 0 &&
                 op_[2] == std::tuple_size_v<U>,
             insn, "a fixed array of the C++ field's length and element");
      if constexpr (kMode == Mode::kToC) std::memcpy(c, v.data(), sizeof(E) * v.size());
      if constexpr (kMode == Mode::kFromC) std::memcpy(v.data(), c, sizeof(E) * v.size());
      op_ += 3;
    } else if constexpr (IsVector<U>::value) {
      sequence(name, insn, c, v);
    } else {  // a nested message
      expect(name, type == DDS_OP_VAL_EXT && DDS_OP_TYPE_FLAGS(insn) == 0 && DDS_OP_FLAGS(insn) == 0, insn,
             "a nested struct");
      Walk sub(type_, op_ + DDS_OP_ADR_JSR(op_[2]), c, arena_, this, name);
      U::fields(v, sub);
      sub.end();
      op_ += DDS_OP_ADR_JMP(op_[2]);
    }
  }

  template <class V>
  void sequence(std::string_view name, std::uint32_t insn, Byte* c, V& v) {
    using E = typename std::remove_const_t<V>::value_type;
    static_assert(!std::is_same_v<E, bool>, "std::vector<bool> has no contiguous storage to lend");
    const bool seq = DDS_OP_TYPE(insn) == DDS_OP_VAL_SEQ && DDS_OP_TYPE_FLAGS(insn) == 0;
    CSeq s{};
    if constexpr (kMode == Mode::kFromC) std::memcpy(&s, c, sizeof s);
    const auto n = static_cast<std::uint32_t>(v.size());
    if constexpr (kPrimitive<E>) {
      expect(name, seq && DDS_OP_SUBTYPE(insn) == primitive_code<E>() && DDS_OP_FLAGS(insn) == primitive_flags<E>(),
             insn, "a sequence of the C++ field's element");
      if constexpr (kMode == Mode::kToC) s = {n, n, const_cast<E*>(v.data()), false};
      if constexpr (kMode == Mode::kFromC) {
        const E* b = static_cast<const E*>(s._buffer);
        v.assign(b, b + s._length);
      }
      op_ += 2;
    } else if constexpr (std::is_same_v<E, std::string>) {
      expect(name, seq && DDS_OP_SUBTYPE(insn) == DDS_OP_VAL_STR && DDS_OP_FLAGS(insn) == 0, insn,
             "a sequence of unbounded strings");
      if constexpr (kMode == Mode::kToC) {
        auto* b = static_cast<unsigned char*>(n ? arena_->zeroed(n * sizeof(char*)) : nullptr);
        for (std::uint32_t i = 0; i < n; ++i) put_string(b + i * sizeof(char*), v[i]);
        s = {n, n, b, false};
      }
      if constexpr (kMode == Mode::kFromC) {
        v.resize(s._length);
        const auto* b = static_cast<const unsigned char*>(s._buffer);
        for (std::uint32_t i = 0; i < s._length; ++i) get_string(b + i * sizeof(char*), v[i]);
      }
      op_ += 2;
    } else {
      expect(name, seq && DDS_OP_SUBTYPE(insn) == DDS_OP_VAL_STU && DDS_OP_FLAGS(insn) == 0, insn,
             "a sequence of structs");
      const std::uint32_t size = op_[2];
      const std::uint32_t* sub_ops = op_ + DDS_OP_ADR_JSR(op_[3]);
      if constexpr (kMode == Mode::kCheck) {
        const E e{};
        Walk sub(type_, sub_ops, nullptr, arena_, this, name);
        E::fields(e, sub);
        sub.end();
      } else {
        const std::uint32_t len = kMode == Mode::kToC ? n : s._length;
        Byte* b;
        if constexpr (kMode == Mode::kToC) {
          b = static_cast<Byte*>(len ? arena_->zeroed(std::size_t{len} * size) : nullptr);
          s = {len, len, b, false};
        } else {
          b = static_cast<Byte*>(s._buffer);
          v.resize(len);
        }
        for (std::uint32_t i = 0; i < len; ++i) {
          Walk sub(type_, sub_ops, b + std::size_t{i} * size, arena_, this, name);
          E::fields(v[i], sub);
          sub.end();
        }
      }
      op_ += DDS_OP_ADR_JMP(op_[3]);
    }
    if constexpr (kMode == Mode::kToC) std::memcpy(c, &s, sizeof s);
  }

  static void put_string(unsigned char* c, const std::string& s) {
    const char* p = s.c_str();  // borrowed: dds_write serialises before it returns
    std::memcpy(c, &p, sizeof p);
  }
  static void get_string(const unsigned char* c, std::string& s) {
    const char* p;
    std::memcpy(&p, c, sizeof p);
    if (p) {
      s.assign(p);
    } else {
      s.clear();
    }
  }

  Byte* at(std::uint32_t offset) const { return kMode == Mode::kCheck ? nullptr : c_ + offset; }

  // The instruction for the field `name`, which must be a member's (ADR).
  std::uint32_t next(std::string_view name) const {
    if (kMode == Mode::kCheck && DDS_OP(*op_) != DDS_OP_ADR)
      fail(name, "fields() lists a field after the IDL type's last member");
    return *op_;
  }
  void expect(std::string_view name, bool ok, std::uint32_t insn, const char* want) const {
    if (kMode == Mode::kCheck && !ok) {
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%08x", insn);
      fail(name, std::string("the C++ field wants ") + want + ", the IDL member's instruction is " + hex);
    }
  }
  [[noreturn]] void fail(std::string_view name, const std::string& what) const {
    std::string path(name);
    for (const Walk* w = this; w && !w->name_.empty(); w = w->parent_) {
      path = std::string(w->name_) + (path.empty() ? "" : ".") + path;
    }
    throw std::logic_error("ros_types: " + std::string(type_) + (path.empty() ? "" : " field '" + path + "'") +
                           " does not match its idlc type: " + what);
  }

  std::string_view type_;
  const std::uint32_t* op_;
  Byte* c_;
  Arena* arena_;
  const Walk* parent_;
  std::string_view name_;
};

/// Walks a default M against `desc`'s instructions, visiting every nested and element type once;
/// throws std::logic_error naming the first field that does not match.
template <class M>
void check_fields(const dds_topic_descriptor_t& desc) {
  const M m{};
  Walk<Mode::kCheck> w(M::kRosType, desc.m_ops, nullptr, nullptr);
  M::fields(m, w);
  w.end();
}

}  // namespace quadcosim::dds::idl_walk
