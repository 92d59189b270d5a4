# The ParkourLab service image: `docker-compose up` runs it with a Dask scheduler and worker.
FROM python:3.11-slim
WORKDIR /opt/parkourlab
COPY pyproject.toml README.md LICENSE ./
COPY sim_core sim_core
COPY experiments experiments
COPY backend backend
COPY frontend frontend
COPY cli cli
COPY parkourlab parkourlab
RUN pip install --no-cache-dir ".[postgres]"
ENV PARKOUR_DATA_DIR=/data \
    PARKOUR_CACHE_DIR=/data/cache
EXPOSE 8000 8001 8786
CMD ["parkour", "serve", "--host", "0.0.0.0", "--data-dir", "/data"]
