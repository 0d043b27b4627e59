// A plain libmodbus TCP server, written the way most libmodbus users write one (the pattern of
// libmodbus' tests/bandwidth-server-many-up.c): one flat mapping, select() over the listener and
// the clients, modbus_receive + modbus_reply per ready client. It is the yardstick for what a
// user would get without plcemud, so it deliberately has no tuning of its own.

#include <modbus.h>
#include <netinet/in.h>
#include <sys/select.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

int main(int argc, char** argv) {
    if (argc != 3 || std::string(argv[1]) != "--port") {
        std::fprintf(stderr, "usage: %s --port N\n", argv[0]);
        return 2;
    }
    const std::unique_ptr<modbus_t, decltype(&modbus_free)> ctx(
        modbus_new_tcp("127.0.0.1", std::atoi(argv[2])), &modbus_free);
    const std::unique_ptr<modbus_mapping_t, decltype(&modbus_mapping_free)> mapping(
        modbus_mapping_new(10000, 10000, 10000, 10000), &modbus_mapping_free);
    if (!ctx || !mapping) {
        std::fprintf(stderr, "libmodbus_peer: %s\n", modbus_strerror(errno));
        return 1;
    }

    const int listener = modbus_tcp_listen(ctx.get(), 64);
    if (listener < 0) {
        std::fprintf(stderr, "libmodbus_peer: listen: %s\n", modbus_strerror(errno));
        return 1;
    }

    fd_set watched;
    FD_ZERO(&watched);
    FD_SET(listener, &watched);
    int fd_max = listener;
    uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];

    for (;;) {
        fd_set ready = watched;
        if (select(fd_max + 1, &ready, nullptr, nullptr, nullptr) < 0) {
            std::perror("libmodbus_peer: select");
            return 1;
        }
        for (int fd = 0; fd <= fd_max; ++fd) {
            if (!FD_ISSET(fd, &ready)) continue;
            if (fd == listener) {
                const int client = accept(listener, nullptr, nullptr);
                if (client < 0) continue;
                FD_SET(client, &watched);
                if (client > fd_max) fd_max = client;
                continue;
            }
            modbus_set_socket(ctx.get(), fd);
            const int rc = modbus_receive(ctx.get(), query);
            if (rc > 0) {
                modbus_reply(ctx.get(), query, rc, mapping.get());
            } else if (rc < 0) {
                close(fd);
                FD_CLR(fd, &watched);
            }
        }
    }
}
