// src/core/option_rows.cc — what every options table shares (posefilter/option_rows.h): names,
// value text, ranges and their check, Markdown.
#include "posefilter/option_rows.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace posefilter {

namespace {

template <class T>
std::string ShortestNumberText(T v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  if (std::isfinite(v) && v == std::trunc(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v));
  // The shortest digits that read back, fixed-point down to 1e-4 ("0.0001", not "1e-04").
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general);
  return std::string(buf, r.ptr);
}

bool RowInRange(double v, const OptionInfo& f) {
  if (!std::isfinite(v)) return false;
  if (f.lo_open ? !(v > f.lo) : !(v >= f.lo)) return false;
  if (f.hi_open ? !(v < f.hi) : !(v <= f.hi)) return false;
  return true;
}

// The elements of a kDoubles field (a std::array<double, count>: its elements start at its address).
const double* DoublesOf(const void* field) { return static_cast<const double*>(field); }

// Reads one number of the field's type from the whole of `text`.
template <class T>
bool ReadNumberText(const std::string& text, T* out) {
  if (text.empty()) return false;
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, *out);
  return r.ec == std::errc() && r.ptr == end;
}

}  // namespace

std::string OptionNumberText(double v) { return ShortestNumberText(v); }
std::string OptionNumberText(float v) { return ShortestNumberText(v); }

OptionInfo MakeOptionRow(const char* name, const char* field, void* (*ref)(void*), OptionType type, int count,
                         const std::type_info* owner, const char* group, OptionRange range, const char* help) {
  return OptionInfo{name,    field,   group,   help,  type,    range.lo, range.hi, range.lo_open, range.hi_open,
                    nullptr, 0u,      nullptr, false, nullptr, count,    owner,    ref};
}

void OptionInfo::CheckOwner(const std::type_info& t) const {
  if (owner == nullptr || *owner != t)
    throw std::logic_error(std::string("option row '") + name + "' is not a field of " + t.name());
}

std::string OptionInfo::Name(OptionNaming naming) const {
  switch (naming) {
    case OptionNaming::kField:
      return field;
    case OptionNaming::kCli:
      return std::string("--") + name;
    case OptionNaming::kPython: {
      if (python != nullptr) return python;
      std::string s = name;
      for (char& c : s)
        if (c == '-') c = '_';
      return s;
    }
  }
  return name;
}

std::string OptionInfo::ValueTextAt(const void* p) const {
  switch (type) {
    case OptionType::kBool: return *static_cast<const bool*>(p) ? "true" : "false";
    case OptionType::kInt: return std::to_string(*static_cast<const int*>(p));
    case OptionType::kFloat: return ShortestNumberText(*static_cast<const float*>(p));
    case OptionType::kDouble: return ShortestNumberText(*static_cast<const double*>(p));
    case OptionType::kString: return *static_cast<const std::string*>(p);
    case OptionType::kUint64: return std::to_string(*static_cast<const std::uint64_t*>(p));
    case OptionType::kDoubles: break;
  }
  std::string s;
  for (int i = 0; i < count; ++i) {
    if (i > 0) s += ',';
    s += ShortestNumberText(DoublesOf(p)[i]);
  }
  return s;
}

bool OptionInfo::SameValueAt(const void* a, const void* b) const {
  switch (type) {
    case OptionType::kBool: return *static_cast<const bool*>(a) == *static_cast<const bool*>(b);
    case OptionType::kInt: return *static_cast<const int*>(a) == *static_cast<const int*>(b);
    case OptionType::kFloat: return *static_cast<const float*>(a) == *static_cast<const float*>(b);
    case OptionType::kDouble: return *static_cast<const double*>(a) == *static_cast<const double*>(b);
    case OptionType::kString: return *static_cast<const std::string*>(a) == *static_cast<const std::string*>(b);
    case OptionType::kUint64: return *static_cast<const std::uint64_t*>(a) == *static_cast<const std::uint64_t*>(b);
    case OptionType::kDoubles: break;
  }
  return std::equal(DoublesOf(a), DoublesOf(a) + count, DoublesOf(b));
}

bool OptionInfo::SetFromTextAt(void* p, const std::string& text, std::string* why) const {
  bool ok = false;
  switch (type) {
    case OptionType::kBool:
      ok = text == "true" || text == "false";
      if (ok) *static_cast<bool*>(p) = text == "true";
      break;
    case OptionType::kInt: ok = ReadNumberText(text, static_cast<int*>(p)); break;
    case OptionType::kFloat: ok = ReadNumberText(text, static_cast<float*>(p)); break;
    case OptionType::kDouble: ok = ReadNumberText(text, static_cast<double*>(p)); break;
    case OptionType::kString: *static_cast<std::string*>(p) = text; ok = true; break;
    case OptionType::kUint64: ok = ReadNumberText(text, static_cast<std::uint64_t*>(p)); break;
    case OptionType::kDoubles: {
      std::vector<double> v;
      std::size_t at = 0;
      for (ok = true; ok && at <= text.size();) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        double d = 0;
        ok = ReadNumberText(text.substr(at, comma - at), &d);
        v.push_back(d);
        at = comma + 1;
      }
      ok = ok && int(v.size()) == count;
      if (ok) std::copy(v.begin(), v.end(), static_cast<double*>(p));
      break;
    }
  }
  if (!ok && why) *why = Name(OptionNaming::kField) + ": '" + text + "' does not read as its value";
  return ok;
}

// A range bound as text: "pi" for π (an angle's range), else the number.
static std::string RowBoundText(double v) {
  if (v == M_PI) return "pi";
  if (v == -M_PI) return "-pi";
  return ShortestNumberText(v);
}

std::string OptionInfo::RangeText() const {
  if (choices != nullptr) return choices;
  if (type == OptionType::kBool || type == OptionType::kString) return "";
  if (type == OptionType::kUint64) return "[0, 2^64 - 1]";
  const bool lo_bounded = std::isfinite(lo), hi_bounded = std::isfinite(hi);
  if (lo_bounded && hi_bounded)
    return std::string(lo_open ? "(" : "[") + RowBoundText(lo) + ", " + RowBoundText(hi) + (hi_open ? ")" : "]");
  if (lo_bounded) return std::string(lo_open ? "> " : ">= ") + RowBoundText(lo);
  if (hi_bounded) return std::string(hi_open ? "< " : "<= ") + RowBoundText(hi);
  return "";
}

std::vector<std::string> OptionInfo::Choices() const {
  std::vector<std::string> out;
  if (choices == nullptr) return out;
  for (std::string c = choices;;) {
    const std::size_t bar = c.find('|');
    out.push_back(c.substr(0, bar));
    if (bar == std::string::npos) return out;
    c = c.substr(bar + 1);
  }
}

const OptionInfo* FindOptionRow(std::span<const OptionInfo> rows, const std::string& key) {
  for (const OptionInfo& f : rows)
    if (key == f.field || key == f.name || key == f.Name(OptionNaming::kPython)) return &f;
  return nullptr;
}

bool ValidateOptionRows(std::span<const OptionInfo> rows, const void* o, OptionNaming naming, std::string* why) {
  for (const OptionInfo& f : rows) {
    const void* p = f.ref(const_cast<void*>(o));
    auto fail = [&](const std::string& value) {
      if (why) {
        const std::string range = f.RangeText();
        const bool interval = !range.empty() && (range[0] == '[' || range[0] == '(');
        *why = f.Name(naming) + " must be " + (f.choices ? "one of " : interval ? "in " : "") + range + " (got " +
               value + ")";
      }
      return false;
    };
    switch (f.type) {
      case OptionType::kBool:
      case OptionType::kUint64:
        break;  // every value is in range
      case OptionType::kString: {
        const std::vector<std::string> choices = f.Choices();
        const std::string& v = *static_cast<const std::string*>(p);
        if (!choices.empty() && std::find(choices.begin(), choices.end(), v) == choices.end())
          return fail("'" + v + "'");
        break;
      }
      case OptionType::kInt:
        if (!RowInRange(*static_cast<const int*>(p), f)) return fail(f.ValueTextAt(p));
        break;
      case OptionType::kFloat:
        if (!RowInRange(*static_cast<const float*>(p), f)) return fail(f.ValueTextAt(p));
        break;
      case OptionType::kDouble:
        if (!RowInRange(*static_cast<const double*>(p), f)) return fail(f.ValueTextAt(p));
        break;
      case OptionType::kDoubles:
        for (int i = 0; i < f.count; ++i)
          if (!RowInRange(DoublesOf(p)[i], f)) {
            if (why)
              *why = f.Name(naming) + " must each be finite and " + f.RangeText() + " (got " +
                     ShortestNumberText(DoublesOf(p)[i]) + ")";
            return false;
          }
        break;
    }
  }
  return true;
}

std::string OptionRowsMarkdown(std::span<const OptionInfo> rows, const void* defaults) {
  std::string md =
      "| option | Python | C++ field | default | range | meaning |\n"
      "|---|---|---|---|---|---|\n";
  for (const OptionInfo& f : rows) {
    std::string range = f.RangeText();
    std::replace(range.begin(), range.end(), '|', '/');
    md += "| `--" + std::string(f.name) + "` | `" + f.Name(OptionNaming::kPython) + "` | `" + f.field + "` | " +
          f.ValueTextAt(f.ref(const_cast<void*>(defaults))) + " | " + range + " | " + f.help + " |\n";
  }
  return md;
}

std::string OptionSetMarkdown(const std::string& title, const std::string& intro, std::span<const OptionInfo> rows,
                              const void* defaults) {
  return "\n## " + title + "\n\n" + intro + "\n\n" + OptionRowsMarkdown(rows, defaults);
}

}  // namespace posefilter
