// SPDX-License-Identifier: Apache-2.0
#include "viewer/view_server.h"

#include "common/runtime/ascii.h"
#include "common/runtime/loop_stats.h"
#include "viewer/view_protocol.h"

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <optional>

namespace impetus::view {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

// A request gets 10 s to arrive whole (a stalled or trickling client is closed) and may carry 8 KiB of headers and
// no body worth reading: the viewer serves files and takes no uploads.
constexpr auto kRequestTimeout = std::chrono::seconds(10);
constexpr std::uint32_t kHeaderLimitBytes = 8 * 1024;

// Counts a connection for as long as it lives.
class ConnectionToken {
 public:
  explicit ConnectionToken(std::shared_ptr<ServerCounters> counters) : counters_(std::move(counters)) {
    ++counters_->open_connections;
  }
  ~ConnectionToken() {
    if (counters_) --counters_->open_connections;
  }
  ConnectionToken(ConnectionToken&& other) noexcept = default;
  ConnectionToken(const ConnectionToken&) = delete;
  ConnectionToken& operator=(const ConnectionToken&) = delete;
  ConnectionToken& operator=(ConnectionToken&&) = delete;
  ServerCounters& counters() const { return *counters_; }

 private:
  std::shared_ptr<ServerCounters> counters_;
};

}  // namespace

// One page over a WebSocket: sends the scene, then frames as the feed has them; reads the page's control messages.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  // `from_page`: the upgrade carried an Origin header, which the server checked is this viewer's own page.
  // `touch_only`: a page's touch socket (/ws/touch): no scene and no frames, only touch messages.
  WsSession(tcp::socket socket, ViewFeed& feed, ConnectionToken token, TouchControl* touch, bool from_page,
            bool touch_only)
      : ws_(std::move(socket)), feed_(feed), token_(std::move(token)), touch_(touch), from_page_(from_page),
        touch_only_(touch_only), page_(++token_.counters().page_serial) {}
  ~WsSession() { leave(); }

  void accept(http::request<http::string_body> request) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kMaxClientMessageBytes);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code error) {
      if (error) return;
      self->open_ = true;
      ++self->token_.counters().pages;
      self->read();
      self->pump(0.0);
    });
  }

  // Called by the server every feed period.
  void pump(double elapsed_s) {
    if (!open_) return;
    if (touch_only_) return write_next();
    if (feed_.scene_serial() != playback_.scene_serial && feed_.scene() != nullptr) {
      playback_ = Playback{};
      playback_.scene_serial = feed_.scene_serial();
      pending_scene_ = feed_.scene();
      if (pending_frame_) ++token_.counters().frames_dropped;
      pending_frame_.reset();
    }
    if (playback_.scene_serial != 0) {
      if (auto frame = feed_.next_frame(playback_, elapsed_s)) {
        if (pending_frame_) ++token_.counters().frames_dropped;
        pending_frame_ = std::move(frame);
      }
    }
    write_next();
  }

  void close() {
    if (!open_) return;
    open_ = false;
    leave();
    ws_.async_close(websocket::close_code::going_away, [self = shared_from_this()](beast::error_code) {});
  }

 private:
  void write_next() {
    if (writing_ || !open_) return;
    const bool reply = pending_scene_ == nullptr && pending_reply_ != nullptr;
    const bool text = pending_scene_ != nullptr || reply;
    std::shared_ptr<const std::string> message = pending_scene_ != nullptr ? std::move(pending_scene_)
                                                 : reply                    ? std::move(pending_reply_)
                                                                            : std::move(pending_frame_);
    pending_scene_.reset();
    if (reply) pending_reply_.reset();
    if (!text) pending_frame_.reset();
    if (message == nullptr) return;
    writing_ = true;
    ws_.text(text);
    ws_.async_write(asio::buffer(*message),
                    [self = shared_from_this(), message, text](beast::error_code error, std::size_t bytes) {
                      self->writing_ = false;
                      if (error) {
                        self->open_ = false;  // the page went away; the session ends with its last handler
                        self->leave();
                        return;
                      }
                      if (!text) ++self->token_.counters().frames_sent;
                      self->token_.counters().bytes_sent += bytes;
                      self->write_next();
                    });
  }

  void read() {
    ws_.async_read(buffer_, [self = shared_from_this()](beast::error_code error, std::size_t) {
      if (error) {  // closed, timed out, or a message over read_message_max: this page ends
        self->open_ = false;
        self->leave();
        return;
      }
      const std::string text = beast::buffers_to_string(self->buffer_.data());
      self->buffer_.consume(self->buffer_.size());
      const nlohmann::json message = nlohmann::json::parse(text, nullptr, false);
      bool ok = false;
      if (!message.is_discarded() && message.is_object() && message.contains("touch")) {
        // Touch messages go to the touch control (view_protocol.h §4); a server without one answers every take
        // "unavailable".
        nlohmann::json reply = self->touch_ != nullptr
                                   ? self->touch_->on_message(self->page_, self->from_page_, message, ok)
                                   : TouchControl::without_touch(message, ok);
        if (ok && !reply.is_null()) self->send_text(reply.dump());
      } else {
        ok = !self->touch_only_ && !message.is_discarded() && self->feed_.control(self->playback_, message);
      }
      if (!ok) {
        self->close_with(websocket::close_code::policy_error);
        return;
      }
      self->pump(0.0);
      self->read();
    });
  }

  // The page lets go of the web hand if it held it; once.
  void leave() {
    if (touch_ != nullptr && !left_) touch_->page_closed(page_);
    left_ = true;
  }

  // A reply to this page alone, sent before the next frame (at most one waits: a newer reply replaces it).
  void send_text(std::string text) {
    pending_reply_ = std::make_shared<const std::string>(std::move(text));
    write_next();
  }

  void close_with(websocket::close_code code) {
    open_ = false;
    leave();
    ws_.async_close(code, [self = shared_from_this()](beast::error_code) {});
  }

  websocket::stream<beast::tcp_stream> ws_;
  ViewFeed& feed_;
  ConnectionToken token_;
  beast::flat_buffer buffer_;
  Playback playback_;
  std::shared_ptr<const std::string> pending_scene_;
  std::shared_ptr<const std::string> pending_frame_;
  std::shared_ptr<const std::string> pending_reply_;
  TouchControl* touch_;
  bool from_page_;
  bool touch_only_;
  std::uint64_t page_;
  bool left_ = false;
  bool open_ = false;
  bool writing_ = false;
};

namespace {

// One HTTP connection: serves the page's files, or hands /ws over to a WsSession.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, const WebRoot& web, ViewFeed& feed, ConnectionToken token,
              std::vector<std::weak_ptr<WsSession>>& pages, const HostRule& host_rule, TouchControl* touch)
      : stream_(std::move(socket)), web_(web), feed_(feed), token_(std::move(token)), pages_(pages),
        host_rule_(host_rule), touch_(touch) {}

  void read() {
    parser_.emplace();
    parser_->header_limit(kHeaderLimitBytes);
    parser_->body_limit(kMaxClientMessageBytes);
    stream_.expires_after(kRequestTimeout);
    http::async_read(stream_, buffer_, *parser_, [self = shared_from_this()](beast::error_code error, std::size_t) {
      self->on_read(error);
    });
  }

 private:
  void on_read(beast::error_code error) {
    if (error == http::error::body_limit || error == http::error::header_limit) {
      return answer(http::status::payload_too_large, "request too large\n", false);
    }
    if (error == http::error::end_of_stream || error) {
      beast::error_code ignored;
      stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
      return;
    }
    ++token_.counters().http_requests;
    http::request<http::string_body> request = parser_->release();
    const std::string target(request.target());
    // Another site's page (DNS rebinding, or a cross-site WebSocket) is refused before anything is served.
    const auto header = [&](http::field field) {
      const beast::string_view value = request[field];
      return std::string_view(value.data(), value.size());
    };
    const std::string_view host = header(http::field::host);
    std::string problem = host_problem(host, host_rule_);
    if (problem.empty()) problem = origin_problem(header(http::field::origin), host);
    if (!problem.empty()) {
      ++token_.counters().foreign_requests;
      return answer(http::status::forbidden, problem + "\n", false);
    }
    if (websocket::is_upgrade(request)) {
      if (target != "/ws" && target != "/ws/touch") {
        return answer(http::status::not_found, "no WebSocket at " + target + " (use /ws, or /ws/touch)\n", false);
      }
      stream_.expires_never();  // the WebSocket keeps its own timeouts
      const bool from_page = !header(http::field::origin).empty();  // and it passed origin_problem above
      auto page = std::make_shared<WsSession>(stream_.release_socket(), feed_, std::move(token_), touch_, from_page,
                                              target == "/ws/touch");
      pages_.push_back(page);
      page->accept(std::move(request));
      return;
    }
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      return answer(http::status::method_not_allowed, "only GET and HEAD\n", request.keep_alive());
    }
    const std::optional<std::filesystem::path> file = web_.file_for(target);
    if (!file) return answer(http::status::not_found, "not found: " + target + "\n", request.keep_alive());
    http::file_body::value_type body;
    beast::error_code open_error;
    body.open(file->c_str(), beast::file_mode::scan, open_error);
    if (open_error) return answer(http::status::not_found, "not found: " + target + "\n", request.keep_alive());
    auto response = std::make_shared<http::response<http::file_body>>(http::status::ok, request.version());
    response->set(http::field::content_type, std::string(content_type(*file)));
    response->set(http::field::cache_control, "no-cache");
    response->keep_alive(request.keep_alive());
    response->body() = std::move(body);
    response->prepare_payload();
    const bool head = request.method() == http::verb::head;
    if (head) response->body().close();
    send(response, head);
  }

  void answer(http::status status, const std::string& text, bool keep_alive) {
    ++token_.counters().http_errors;
    auto response = std::make_shared<http::response<http::string_body>>(status, 11);
    response->set(http::field::content_type, "text/plain; charset=utf-8");
    response->keep_alive(keep_alive);
    response->body() = text;
    response->prepare_payload();
    send(response, false);
  }

  template <class Response>
  void send(const std::shared_ptr<Response>& response, bool head_only) {
    const auto done = [self = shared_from_this(), response](beast::error_code error, std::size_t) {
      if (error || !response->keep_alive()) {
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
        return;
      }
      self->read();
    };
    if (head_only) {
      auto serializer = std::make_shared<http::response_serializer<typename Response::body_type>>(*response);
      http::async_write_header(stream_, *serializer,
                               [done, serializer](beast::error_code error, std::size_t bytes) { done(error, bytes); });
    } else {
      http::async_write(stream_, *response, done);
    }
  }

  beast::tcp_stream stream_;
  const WebRoot& web_;
  ViewFeed& feed_;
  ConnectionToken token_;
  std::vector<std::weak_ptr<WsSession>>& pages_;
  HostRule host_rule_;  // a copy: a session may outlive the server
  TouchControl* touch_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

ViewServer::ViewServer(asio::io_context& io, const tcp::endpoint& endpoint, const WebRoot& web, ViewFeed& feed,
                       std::vector<std::string> host_names, TouchControl* touch)
    : io_(io), acceptor_(io), timer_(io), web_(web), feed_(feed), touch_(touch),
      counters_(std::make_shared<ServerCounters>()) {
  acceptor_.open(endpoint.protocol());
  acceptor_.set_option(asio::socket_base::reuse_address(true));
  acceptor_.bind(endpoint);
  acceptor_.listen(asio::socket_base::max_listen_connections);
  host_rule_.port = acceptor_.local_endpoint().port();
  host_rule_.loopback_only = endpoint.address().is_loopback();
  host_rule_.names = std::move(host_names);
  char machine[256] = {};
  if (gethostname(machine, sizeof machine - 1) == 0 && machine[0] != '\0') {
    host_rule_.names.push_back(ascii_lower(machine));
  }
}

ViewServer::~ViewServer() = default;

void ViewServer::start() {
  last_tick_ns_ = monotonic_now_ns();
  accept();
  tick();
}

void ViewServer::stop() {
  if (stopped_) return;
  stopped_ = true;
  beast::error_code ignored;
  acceptor_.close(ignored);
  timer_.cancel();
  for (const auto& weak : pages_) {
    if (auto page = weak.lock()) page->close();
  }
}

void ViewServer::accept() {
  acceptor_.async_accept([this](beast::error_code error, tcp::socket socket) {
    if (stopped_ || error == asio::error::operation_aborted) return;
    if (!error) {
      if (counters_->open_connections >= kMaxConnections) {
        ++counters_->refused;
        beast::error_code ignored;
        socket.close(ignored);
      } else {
        std::make_shared<HttpSession>(std::move(socket), web_, feed_, ConnectionToken(counters_), pages_, host_rule_,
                                      touch_)
            ->read();
      }
    }
    accept();  // also after an error (e.g. out of descriptors): the next connection may succeed
  });
}

void ViewServer::tick() {
  if (stopped_) return;
  const std::int64_t now_ns = monotonic_now_ns();
  const double elapsed_s = static_cast<double>(now_ns - last_tick_ns_) * 1e-9;
  last_tick_ns_ = now_ns;
  feed_.poll();
  std::erase_if(pages_, [](const std::weak_ptr<WsSession>& page) { return page.expired(); });
  for (const auto& weak : pages_) {
    if (auto page = weak.lock()) page->pump(elapsed_s);
  }
  timer_.expires_after(std::chrono::duration_cast<asio::steady_timer::duration>(
      std::chrono::duration<double>(feed_.poll_period_s())));
  timer_.async_wait([this](beast::error_code error) {
    if (!error) tick();
  });
}

}  // namespace impetus::view
