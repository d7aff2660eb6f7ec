# Multi-stage build: compile in the Rust image, run from a slim Debian with only the binary,
# the reference configs and the migrations' target directory.
FROM rust:1-bookworm AS build
WORKDIR /src
ARG RAILWEAR_GIT_HASH=""
ENV RAILWEAR_GIT_HASH=${RAILWEAR_GIT_HASH}
COPY Cargo.toml Cargo.lock ./
COPY src ./src
# Workspace members (dev-only: the image builds and ships the railwear binary alone).
COPY testkit ./testkit
COPY bench ./bench
COPY migrations ./migrations
COPY configs ./configs
COPY api ./api
RUN cargo build --release --locked --bin railwear

FROM debian:bookworm-slim
RUN useradd --system --home /var/lib/railwear --create-home railwear
WORKDIR /app
COPY --from=build /src/target/release/railwear /usr/local/bin/railwear
COPY configs ./configs
USER railwear
ENV DATABASE_URL=sqlite:///var/lib/railwear/railwear.db?mode=rwc \
    RAILWEAR_LISTEN=0.0.0.0:8080 \
    RAILWEAR_LOG_FORMAT=json
EXPOSE 8080
VOLUME ["/var/lib/railwear"]
ENTRYPOINT ["railwear"]
CMD ["serve"]
