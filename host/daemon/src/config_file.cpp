#include "tonus/host/daemon/config_file.hpp"

#include <toml++/toml.h>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace tonus::daemon {
namespace {

// A node as the file spells it (for error messages): strings in double
// quotes, numbers as short as they round-trip.
std::string node_text(const toml::node& n) {
  if (const auto v = n.value_exact<std::string>()) return fmt::format("\"{}\"", *v);
  if (n.is_floating_point()) return fmt::format("{}", *n.value<double>());
  if (n.is_integer()) return fmt::format("{}", *n.value<std::int64_t>());
  if (const auto v = n.value_exact<bool>()) return *v ? "true" : "false";
  if (const toml::array* a = n.as_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < a->size(); ++i) out += (i > 0 ? ", " : "") + node_text((*a)[i]);
    return out + "]";
  }
  std::ostringstream o;
  n.visit([&o](const auto& v) { o << v; });
  return o.str();
}

// Reads the keys of one table, remembering which it saw, so unknown ones are
// reported by name.
class TableReader {
 public:
  TableReader(const toml::table* t, std::string prefix) : t_(t), prefix_(std::move(prefix)) {}

  [[nodiscard]] std::string key(std::string_view k) const { return prefix_ + std::string(k); }

  template <typename T>
  void get(std::string_view k, T& out) {
    if (!error_.empty() || t_ == nullptr) return;
    seen_.emplace_back(k);
    const toml::node* n = t_->get(k);
    if (n == nullptr) return;
    if constexpr (std::is_same_v<T, bool>) {
      if (const auto v = n->value_exact<bool>())
        out = *v;
      else
        fail(k, *n, "a boolean");
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (const auto v = n->value_exact<std::string>())
        out = *v;
      else
        fail(k, *n, "a string");
    } else if constexpr (std::is_floating_point_v<T>) {
      if (const auto v = n->value<double>(); v && (n->is_floating_point() || n->is_integer()))
        out = *v;
      else
        fail(k, *n, "a number");
    } else {
      const auto v = n->value_exact<std::int64_t>();
      if (!v) {
        fail(k, *n, "an integer");
      } else if (*v < static_cast<std::int64_t>(std::numeric_limits<T>::min()) ||
                 static_cast<std::uint64_t>(*v) > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) {
        error_ = fmt::format("{} = {}: out of range", key(k), *v);
      } else {
        out = static_cast<T>(*v);
      }
    }
  }

  // Milliseconds in the file, seconds in the config.
  void get_ms(std::string_view k, double& seconds) {
    double ms = seconds * 1e3;
    get(k, ms);
    seconds = ms * 1e-3;
  }

  // A string naming one of an enum's values.
  template <typename E, std::size_t N>
  void get_enum(std::string_view k, E& out, const std::array<E, N>& values) {
    std::string s(to_string(out));
    get(k, s);
    if (!error_.empty()) return;
    for (const E v : values) {
      if (to_string(v) == s) {
        out = v;
        return;
      }
    }
    std::string allowed;
    for (const E v : values) allowed += (allowed.empty() ? "" : ", ") + std::string(to_string(v));
    error_ = fmt::format("{} = \"{}\": must be one of {}", key(k), s, allowed);
  }

  // A key read by other means (arrays): known, not read here.
  void mark(std::string_view k) { seen_.emplace_back(k); }

  void finish() {
    if (!error_.empty() || t_ == nullptr) return;
    for (const auto& [k, v] : *t_) {
      if (std::find(seen_.begin(), seen_.end(), k.str()) == seen_.end()) {
        error_ = fmt::format("{}: unknown key", key(k.str()));
        return;
      }
    }
  }

  void fail(std::string_view k, const toml::node& n, std::string_view want) {
    error_ = fmt::format("{} = {}: must be {}", key(k), node_text(n), want);
  }

  std::string error_;

 private:
  const toml::table* t_;
  std::string prefix_;
  std::vector<std::string> seen_;
};

std::string read_levels(const toml::node* n, Levels& out) {
  if (n == nullptr) return {};
  if (const auto v = n->value<double>()) {
    out.fill(*v);
    return {};
  }
  const toml::array* a = n->as_array();
  if (a == nullptr || a->size() != out.size()) return "must be a number or an array of 4 numbers";
  for (std::size_t i = 0; i < out.size(); ++i) {
    const auto v = (*a)[i].value<double>();
    if (!v) return "must be a number or an array of 4 numbers";
    out[i] = *v;
  }
  return {};
}

std::string read_gifts(const toml::node* n, std::vector<ScheduledGift>& out) {
  if (n == nullptr) return {};
  const toml::array* a = n->as_array();
  if (a == nullptr) return "demo.gifts: must be an array of tables {at_s, kind, bone}";
  out.clear();
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::table* t = (*a)[i].as_table();
    if (t == nullptr) return fmt::format("demo.gifts[{}]: must be a table {{at_s, kind, bone}}", i);
    ScheduledGift g;
    TableReader r(t, fmt::format("demo.gifts[{}].", i));
    r.get("at_s", g.at_s);
    r.get("kind", g.kind);
    r.get("bone", g.bone);
    r.finish();
    if (!r.error_.empty()) return r.error_;
    out.push_back(g);
  }
  return {};
}

constexpr std::array kBandSources{BandSource::sim, BandSource::socket,  BandSource::hid,
                                  BandSource::can, BandSource::candump, BandSource::none};
constexpr std::array kSimLinks{SimLink::hid, SimLink::can};
constexpr std::array kTrackerSources{TrackerSource::bvh, TrackerSource::vmc, TrackerSource::none};
constexpr std::array kBalanceModes{balance::BalanceMode::off, balance::BalanceMode::offline,
                                   balance::BalanceMode::online};
constexpr std::array kVmcModes{VmcMode::performer, VmcMode::trackers};
constexpr std::array kFeedforwards{FeedforwardChoice::simulation, FeedforwardChoice::inverse_dynamics,
                                   FeedforwardChoice::none};

std::string read_all(const toml::table& root, DaemonConfig& c) {
  static constexpr std::array<std::string_view, 8> kTables{"band",    "tracker", "physics", "output",
                                                           "control", "viewer",  "log",     "demo"};
  for (const auto& [k, v] : root) {
    if (std::find(kTables.begin(), kTables.end(), k.str()) == kTables.end()) {
      return fmt::format("{}: unknown table (known: band, tracker, physics, output, control, viewer, log, demo)",
                         k.str());
    }
    if (!v.is_table()) return fmt::format("{}: must be a table", k.str());
  }
  {
    BandConfig& b = c.band;
    TableReader r(root["band"].as_table(), "band.");
    r.get_enum("source", b.source, kBandSources);
    r.get("sim_path", b.sim_path);
    r.get("sim_synthetic", b.sim_synthetic);
    r.get("sim_recording", b.sim_recording);
    r.get("sim_seconds", b.sim_seconds);
    r.get("sim_seed", b.sim_seed);
    r.mark("sim_args");
    r.get_enum("sim_link", b.sim_link, kSimLinks);
    r.get("sim_socket", b.sim_socket);
    r.get("vid", b.vid);
    r.get("pid", b.pid);
    r.get("serial", b.serial);
    r.get("can_interface", b.can_interface);
    r.get("can_node", b.can_node);
    r.get("can_id_base", b.can_id_base);
    r.get("candump_path", b.candump_path);
    r.get("candump_loop", b.candump_loop);
    r.get_ms("stale_after_ms", b.stiffness.stale_after_s);
    r.get_ms("ease_ms", b.stiffness.ease_s);
    r.get_ms("time_sync_interval_ms", b.time_sync_interval_s);
    r.mark("safe_stiffness");
    r.finish();
    if (!r.error_.empty()) return r.error_;
    if (const toml::table* t = root["band"].as_table(); t != nullptr && t->get("sim_args") != nullptr) {
      const toml::array* a = t->get("sim_args")->as_array();
      if (a == nullptr) return "band.sim_args: must be an array of strings";
      b.sim_args.clear();
      for (const toml::node& n : *a) {
        const auto v = n.value_exact<std::string>();
        if (!v) return "band.sim_args: must be an array of strings";
        b.sim_args.push_back(*v);
      }
    }
    if (const toml::table* t = root["band"].as_table(); t != nullptr && t->get("safe_stiffness") != nullptr) {
      if (std::string e = read_levels(t->get("safe_stiffness"), b.stiffness.safe_default); !e.empty()) {
        return fmt::format("band.safe_stiffness = {}: {}", node_text(*t->get("safe_stiffness")), e);
      }
    }
  }
  {
    TrackerConfig& t = c.tracker;
    TableReader r(root["tracker"].as_table(), "tracker.");
    r.get_enum("source", t.source, kTrackerSources);
    r.get("bvh_path", t.bvh_path);
    r.get("bvh_loop", t.bvh_loop);
    r.get_enum("balance", t.balance, kBalanceModes);
    r.get_ms("balance_lookahead_ms", t.balance_lookahead_s);
    r.get_enum("vmc_mode", t.vmc_mode, kVmcModes);
    r.get("listen_address", t.listen_address);
    r.get("listen_port", t.listen_port);
    r.get_ms("delay_ms", t.buffer.delay_s);
    r.get_ms("hold_ms", t.buffer.hold_s);
    r.get_ms("ease_ms", t.buffer.ease_s);
    r.get_ms("recover_ms", t.buffer.recover_s);
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  {
    PhysicsConfig& p = c.physics;
    TableReader r(root["physics"].as_table(), "physics.");
    r.get("rate_hz", p.rate_hz);
    r.get("max_catch_up_ticks", p.max_catch_up_ticks);
    r.get("realtime_priority", p.realtime_priority);
    r.get("lock_memory", p.lock_memory);
    r.get_enum("feedforward", p.feedforward, kFeedforwards);
    r.get("stiffness_rate_per_s", p.stiffness_rate_per_s);
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  {
    OutputConfig& o = c.output;
    TableReader r(root["output"].as_table(), "output.");
    r.get("enabled", o.enabled);
    r.get("host", o.host);
    r.get("port", o.port);
    r.get("rate_hz", o.rate_hz);
    r.get("bundle", o.bundle);
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  {
    ControlConfig& k = c.control;
    TableReader r(root["control"].as_table(), "control.");
    r.get("enabled", k.enabled);
    r.get("address", k.address);
    r.get("port", k.port);
    r.get("allow_remote", k.allow_remote);
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  {
    ViewerConfig& k = c.viewer;
    TableReader r(root["viewer"].as_table(), "viewer.");
    r.get("enabled", k.enabled);
    r.get("address", k.address);
    r.get("port", k.port);
    r.get("allow_remote", k.allow_remote);
    r.get("rate_hz", k.rate_hz);
    r.get("web_root", k.web_root);
    r.get("vrm", k.vrm);
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  {
    TableReader r(root["log"].as_table(), "log.");
    r.get("level", c.log.level);
    r.get("status_interval_s", c.log.status_interval_s);
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  {
    TableReader r(root["demo"].as_table(), "demo.");
    r.get("seconds", c.demo.seconds);
    if (const toml::table* t = root["demo"].as_table()) {
      if (std::string e = read_gifts(t->get("gifts"), c.demo.gifts); !e.empty()) return e;
    }
    r.mark("gifts");
    r.finish();
    if (!r.error_.empty()) return r.error_;
  }
  return {};
}

}  // namespace

std::string parse_config(std::string_view text, std::string_view source, DaemonConfig& config) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    return fmt::format("{}:{}:{}: {}", source, e.source().begin.line, e.source().begin.column, e.description());
  }
  if (std::string e = read_all(root, config); !e.empty()) return fmt::format("{}: {}", source, e);
  if (std::string e = validate(config); !e.empty()) return fmt::format("{}: {}", source, e);
  return {};
}

std::string load_config(const std::string& path, DaemonConfig& config) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fmt::format("{}: cannot open the config file", path);
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) return fmt::format("{}: cannot read the config file", path);
  return parse_config(ss.str(), path, config);
}

std::string to_toml(const DaemonConfig& c) {
  const auto q = [](const std::string& s) {
    std::ostringstream o;
    o << toml::value<std::string>(s);
    return o.str();
  };
  const auto levels = [](const Levels& l) { return fmt::format("[{}, {}, {}, {}]", l[0], l[1], l[2], l[3]); };
  std::string out;
  const BandConfig& b = c.band;
  out += "# tonusd configuration (every key shown with its effective value)\n\n[band]\n";
  out += fmt::format("source = \"{}\"  # sim, socket, hid, can, candump, none\n", to_string(b.source));
  out += fmt::format("sim_path = {}  # empty: tonus-band-sim beside tonusd\n", q(b.sim_path));
  out += fmt::format("sim_synthetic = {}\nsim_recording = {}\nsim_seconds = {}\nsim_seed = {}\n", q(b.sim_synthetic),
                     q(b.sim_recording), b.sim_seconds, b.sim_seed);
  std::string args;
  for (const std::string& a : b.sim_args) args += (args.empty() ? "" : ", ") + q(a);
  out += fmt::format("sim_args = [{}]\n", args);
  out += fmt::format("sim_link = \"{}\"  # hid, can\nsim_socket = {}\n", to_string(b.sim_link), q(b.sim_socket));
  out += fmt::format("vid = {}\npid = {}\nserial = {}\n", b.vid, b.pid, q(b.serial));
  out += fmt::format("can_interface = {}\ncan_node = {}\ncan_id_base = {}\n", q(b.can_interface), b.can_node,
                     b.can_id_base);
  out += fmt::format("candump_path = {}\ncandump_loop = {}\n", q(b.candump_path), b.candump_loop);
  out += fmt::format("stale_after_ms = {}\nease_ms = {}\nsafe_stiffness = {}\ntime_sync_interval_ms = {}\n",
                     b.stiffness.stale_after_s * 1e3, b.stiffness.ease_s * 1e3, levels(b.stiffness.safe_default),
                     b.time_sync_interval_s * 1e3);
  const TrackerConfig& t = c.tracker;
  out += "\n[tracker]\n";
  out += fmt::format("source = \"{}\"  # bvh, vmc, none\n", to_string(t.source));
  out += fmt::format("bvh_path = {}  # empty: the bundled clip\nbvh_loop = {}\n", q(t.bvh_path), t.bvh_loop);
  out +=
      fmt::format("balance = \"{}\"  # off, offline (bvh), online (bvh or vmc performer)\nbalance_lookahead_ms = {}\n",
                  balance::to_string(t.balance), t.balance_lookahead_s * 1e3);
  out += fmt::format("vmc_mode = \"{}\"  # performer, trackers\n", to_string(t.vmc_mode));
  out += fmt::format("listen_address = {}\nlisten_port = {}\n", q(t.listen_address), t.listen_port);
  out += fmt::format("delay_ms = {}\nhold_ms = {}\nease_ms = {}\nrecover_ms = {}\n", t.buffer.delay_s * 1e3,
                     t.buffer.hold_s * 1e3, t.buffer.ease_s * 1e3, t.buffer.recover_s * 1e3);
  const PhysicsConfig& p = c.physics;
  out += "\n[physics]\n";
  out += fmt::format("rate_hz = {}\nmax_catch_up_ticks = {}\nrealtime_priority = {}\nlock_memory = {}\n", p.rate_hz,
                     p.max_catch_up_ticks, p.realtime_priority, p.lock_memory);
  out += fmt::format("feedforward = \"{}\"  # simulation, inverse_dynamics, none\nstiffness_rate_per_s = {}\n",
                     to_string(p.feedforward), p.stiffness_rate_per_s);
  const OutputConfig& o = c.output;
  out += "\n[output]\n";
  out += fmt::format("enabled = {}\nhost = {}\nport = {}\nrate_hz = {}\nbundle = {}\n", o.enabled, q(o.host), o.port,
                     o.rate_hz, o.bundle);
  out += "\n[control]\n";
  out += fmt::format("enabled = {}\naddress = {}\nport = {}\nallow_remote = {}\n", c.control.enabled,
                     q(c.control.address), c.control.port, c.control.allow_remote);
  out += "\n[viewer]\n";
  out += fmt::format("enabled = {}\naddress = {}\nport = {}\nallow_remote = {}\nrate_hz = {}\nweb_root = {}\n",
                     c.viewer.enabled, q(c.viewer.address), c.viewer.port, c.viewer.allow_remote, c.viewer.rate_hz,
                     q(c.viewer.web_root));
  out += fmt::format("vrm = {}  # a .vrm avatar for the page; empty: none\n", q(c.viewer.vrm));
  out += "\n[log]\n";
  out += fmt::format("level = {}\nstatus_interval_s = {}\n", q(c.log.level), c.log.status_interval_s);
  out += "\n[demo]\n";
  out += fmt::format("seconds = {}\n", c.demo.seconds);
  const std::vector<ScheduledGift> gifts = c.demo.gifts.empty() ? default_demo_gifts(c.demo.seconds) : c.demo.gifts;
  out += "gifts = [\n";
  for (const ScheduledGift& g : gifts) {
    out += fmt::format("  {{ at_s = {}, kind = {}, bone = {} }},\n", g.at_s, q(g.kind), q(g.bone));
  }
  out += "]\n";
  return out;
}

}  // namespace tonus::daemon
