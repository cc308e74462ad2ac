// The tests' WebSocket client: websocketpp's asio client on a thread of its
// own. C++17, as the server's translation unit (src/server.cpp says why).
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include "viewer_fixtures.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>
#pragma GCC diagnostic pop

namespace tonus::viewer::testing {

namespace {
using Client = websocketpp::client<websocketpp::config::asio_client>;
using Hdl = websocketpp::connection_hdl;
}  // namespace

struct WsClient::Impl {
  Client client;
  Hdl hdl;
  std::thread thread;
  mutable std::mutex mutex;
  std::condition_variable changed;
  std::vector<nlohmann::json> received;
  bool open = false;
  bool failed = false;
  bool is_closed = false;
  int refused = 0;
  int code = 0;

  void notify(const std::function<void()>& update) {
    {
      const std::lock_guard<std::mutex> lock(mutex);
      update();
    }
    changed.notify_all();
  }
};

WsClient::WsClient(int port, const std::string& path, const Headers& headers) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.client.clear_access_channels(websocketpp::log::alevel::all);
  d.client.clear_error_channels(websocketpp::log::elevel::all);
  d.client.init_asio();
  d.client.set_open_handler([&d](const Hdl&) { d.notify([&d] { d.open = true; }); });
  d.client.set_fail_handler([&d](const Hdl& hdl) {
    websocketpp::lib::error_code ec;
    const auto con = d.client.get_con_from_hdl(hdl, ec);
    const int status = ec ? 0 : static_cast<int>(con->get_response_code());
    d.notify([&d, status] {
      d.failed = true;
      d.refused = status;
    });
  });
  d.client.set_close_handler([&d](const Hdl& hdl) {
    websocketpp::lib::error_code ec;
    const auto con = d.client.get_con_from_hdl(hdl, ec);
    const int code = ec ? 0 : static_cast<int>(con->get_remote_close_code());
    d.notify([&d, code] {
      d.is_closed = true;
      d.code = code;
    });
  });
  d.client.set_message_handler([&d](const Hdl&, const Client::message_ptr& msg) {
    nlohmann::json doc;
    try {
      doc = nlohmann::json::parse(msg->get_payload());
    } catch (const std::exception&) {
      doc = {{"type", "unparsable"}, {"text", msg->get_payload()}};
    }
    d.notify([&d, &doc] { d.received.push_back(std::move(doc)); });
  });
  websocketpp::lib::error_code ec;
  const auto con = d.client.get_connection("ws://127.0.0.1:" + std::to_string(port) + path, ec);
  if (ec) {
    d.failed = true;
    return;
  }
  for (const auto& [name, value] : headers) con->replace_header(name, value);
  d.hdl = con->get_handle();
  d.client.connect(con);
  d.thread = std::thread([&d] {
    try {
      d.client.run();
    } catch (const std::exception&) {
      d.notify([&d] { d.failed = true; });
    }
  });
}

WsClient::~WsClient() {
  close();
  if (impl_->thread.joinable()) {
    // The close handshake normally ends run(); a server that is gone or
    // stuck must not hold the test up.
    {
      std::unique_lock<std::mutex> lock(impl_->mutex);
      impl_->changed.wait_for(lock, 1000ms, [this] { return impl_->is_closed || impl_->failed; });
    }
    impl_->client.stop();
    impl_->thread.join();
  }
}

bool WsClient::wait_open(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(impl_->mutex);
  impl_->changed.wait_for(lock, timeout, [this] { return impl_->open || impl_->failed; });
  return impl_->open;
}

int WsClient::refused_status() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->refused;
}

void WsClient::send(const std::string& text) {
  websocketpp::lib::error_code ec;
  impl_->client.send(impl_->hdl, text, websocketpp::frame::opcode::text, ec);
}

void WsClient::send_binary(const std::string& bytes) {
  websocketpp::lib::error_code ec;
  impl_->client.send(impl_->hdl, bytes, websocketpp::frame::opcode::binary, ec);
}

void WsClient::close() {
  websocketpp::lib::error_code ec;
  {
    const std::lock_guard<std::mutex> lock(impl_->mutex);
    if (!impl_->open || impl_->is_closed) return;
  }
  impl_->client.close(impl_->hdl, websocketpp::close::status::normal, "test done", ec);
}

std::vector<nlohmann::json> WsClient::messages() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->received;
}

std::optional<nlohmann::json> WsClient::wait_message(const std::function<bool(const nlohmann::json&)>& match,
                                                     std::chrono::milliseconds timeout) {
  std::optional<nlohmann::json> found;
  wait_for(
      [&](const std::vector<nlohmann::json>& all) {
        for (const auto& m : all) {
          if (match(m)) {
            found = m;
            return true;
          }
        }
        return false;
      },
      timeout);
  return found;
}

bool WsClient::wait_for(const std::function<bool(const std::vector<nlohmann::json>&)>& done,
                        std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(impl_->mutex);
  return impl_->changed.wait_for(lock, timeout, [&] { return done(impl_->received); });
}

bool WsClient::wait_closed(std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(impl_->mutex);
  return impl_->changed.wait_for(lock, timeout, [this] { return impl_->is_closed; });
}

bool WsClient::closed() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->is_closed;
}

int WsClient::close_code() const {
  const std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->code;
}

}  // namespace tonus::viewer::testing
