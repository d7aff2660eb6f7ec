//! The [`Store`](super::Store) methods each engine delegates to [`super::portable::Portable`],
//! written once as a macro expanded inside `impl Store for SqliteStore` and
//! `impl Store for PgStore` (a trait impl cannot be split between a generic and a concrete
//! part; the engine's own methods sit beside the expansion). Types are named by full path, so
//! the expansion does not depend on the engine file's imports.

/// The [`Store`](super::Store) methods whose bodies are the
/// [`Portable`](super::portable::Portable) operations, expanded inside each engine's
/// `impl Store` (`portable_store_methods!(Portable<Sqlite>)`, on a type with a `pool` field). The trait's method order is kept in the trait; an impl may list its
/// methods in any order.
macro_rules! portable_store_methods {
    ($shared:ty) => {
        fn ping(&self) -> $crate::store::StoreFuture<'_, ()> {
            Box::pin(<$shared>::ping(&self.pool))
        }

        fn get_job(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::job_records::JobRecord>> {
            Box::pin(async move { <$shared>::job_in(&mut *self.pool.acquire().await?, id).await })
        }

        fn list_jobs(
            &self,
            page: $crate::store::PageRequest,
            filter: $crate::store::JobFilter,
        ) -> $crate::store::StoreFuture<
            '_,
            $crate::store::Page<$crate::store::job_records::JobRecord>,
        > {
            Box::pin(<$shared>::list_jobs(&self.pool, page, filter))
        }

        fn host_leases(
            &self,
            host: &str,
        ) -> $crate::store::StoreFuture<'_, Vec<$crate::store::HostLease>> {
            Box::pin(<$shared>::host_leases(&self.pool, host.to_string()))
        }

        fn release_job(
            &self,
            id: ::uuid::Uuid,
            attempt: i64,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, $crate::store::ReleaseOutcome> {
            Box::pin(<$shared>::release_job(&self.pool, id, attempt, now_ms))
        }

        fn heartbeat(
            &self,
            id: ::uuid::Uuid,
            attempt: i64,
            progress: Option<$crate::store::job_records::JobProgress>,
            now_ms: i64,
            lease_ms: i64,
        ) -> $crate::store::StoreFuture<'_, $crate::store::Heartbeat> {
            Box::pin(<$shared>::heartbeat(
                &self.pool, id, attempt, progress, now_ms, lease_ms,
            ))
        }

        fn finish_job(
            &self,
            id: ::uuid::Uuid,
            attempt: i64,
            finish: $crate::store::Finish,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, bool> {
            Box::pin(<$shared>::finish_job(
                &self.pool, id, attempt, finish, now_ms,
            ))
        }

        fn fan_out(
            &self,
            parent: ::uuid::Uuid,
            attempt: i64,
            fan_out: $crate::store::FanOut,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, $crate::store::FanOutResult> {
            Box::pin(<$shared>::fan_out(
                &self.pool, parent, attempt, fan_out, now_ms,
            ))
        }

        fn children(
            &self,
            parent: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Vec<$crate::store::ChildRecord>> {
            Box::pin(<$shared>::children(&self.pool, parent))
        }

        fn attempts(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Vec<$crate::store::AttemptRecord>> {
            Box::pin(<$shared>::attempts(&self.pool, id))
        }

        fn request_cancel(
            &self,
            id: ::uuid::Uuid,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::job_records::JobRecord>> {
            Box::pin(<$shared>::request_cancel(&self.pool, id, now_ms))
        }

        fn job_counts(
            &self,
        ) -> $crate::store::StoreFuture<'_, Vec<($crate::store::job_records::JobStatus, i64)>> {
            Box::pin(<$shared>::job_counts(&self.pool))
        }

        fn track_blocks(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Vec<$crate::store::TrackBlock>> {
            Box::pin(<$shared>::track_blocks(&self.pool, id))
        }

        fn plot_names(&self, id: ::uuid::Uuid) -> $crate::store::StoreFuture<'_, Vec<String>> {
            Box::pin(<$shared>::plot_names(&self.pool, id))
        }

        fn plot(
            &self,
            id: ::uuid::Uuid,
            name: &str,
        ) -> $crate::store::StoreFuture<'_, Option<String>> {
            Box::pin(<$shared>::plot(&self.pool, id, name.to_string()))
        }

        fn active_sweep(
            &self,
            curve_key: &str,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::job_records::JobRecord>> {
            Box::pin(<$shared>::active_sweep(&self.pool, curve_key.to_string()))
        }

        fn add_measurement(
            &self,
            m: $crate::store::NewMeasurement,
        ) -> $crate::store::StoreFuture<'_, $crate::store::MeasurementRecord> {
            Box::pin(<$shared>::add_measurement(&self.pool, m))
        }

        fn get_rail(
            &self,
            serial: &str,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::RailRecord>> {
            Box::pin(<$shared>::get_rail(&self.pool, serial.to_string()))
        }

        fn list_rails(
            &self,
            page: $crate::store::PageRequest,
        ) -> $crate::store::StoreFuture<'_, $crate::store::Page<$crate::store::RailRecord>> {
            Box::pin(<$shared>::list_rails(&self.pool, page))
        }

        fn measurements(
            &self,
            serial: &str,
            page: $crate::store::PageRequest,
        ) -> $crate::store::StoreFuture<'_, $crate::store::Page<$crate::store::MeasurementRecord>> {
            Box::pin(<$shared>::measurements(
                &self.pool,
                serial.to_string(),
                page,
            ))
        }

        fn latest_measurement(
            &self,
            serial: &str,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::MeasurementRecord>> {
            Box::pin(<$shared>::latest_measurement(
                &self.pool,
                serial.to_string(),
            ))
        }

        fn get_curve(
            &self,
            id: i64,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::CurveRecord>> {
            Box::pin(async move { <$shared>::curve_in(&mut *self.pool.acquire().await?, id).await })
        }

        fn published_curve(
            &self,
            key: &str,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::CurveRecord>> {
            let key = key.to_string();
            Box::pin(
                async move { <$shared>::published_in(&mut *self.pool.acquire().await?, key).await },
            )
        }

        fn list_curves(
            &self,
            page: $crate::store::PageRequest,
            filter: $crate::store::CurveFilter,
        ) -> $crate::store::StoreFuture<'_, $crate::store::Page<$crate::store::CurveRecord>> {
            Box::pin(<$shared>::list_curves(&self.pool, page, filter))
        }

        fn publish_curve(
            &self,
            id: i64,
            published_by: &str,
            force: bool,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, $crate::store::PublishOutcome> {
            let by = published_by.to_string();
            Box::pin(<$shared>::publish_curve(&self.pool, id, by, force, now_ms))
        }

        fn insert_campaign(
            &self,
            campaign: $crate::store::NewCampaign,
        ) -> $crate::store::StoreFuture<'_, $crate::store::CampaignInsert> {
            Box::pin(<$shared>::insert_campaign(&self.pool, campaign))
        }

        fn get_campaign(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::CampaignRecord>> {
            Box::pin(<$shared>::get_campaign(&self.pool, id))
        }

        fn list_campaigns(
            &self,
            page: $crate::store::PageRequest,
        ) -> $crate::store::StoreFuture<'_, $crate::store::Page<$crate::store::CampaignSummary>> {
            Box::pin(<$shared>::list_campaigns(&self.pool, page))
        }

        fn create_token(
            &self,
            name: &str,
            role: $crate::store::Role,
            token_sha256: &str,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, $crate::store::TokenRecord> {
            let (name, sha) = (name.to_string(), token_sha256.to_string());
            Box::pin(<$shared>::create_token(&self.pool, name, role, sha, now_ms))
        }

        fn find_token(
            &self,
            token_sha256: &str,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::TokenRecord>> {
            Box::pin(<$shared>::find_token(&self.pool, token_sha256.to_string()))
        }

        fn list_tokens(&self) -> $crate::store::StoreFuture<'_, Vec<$crate::store::TokenRecord>> {
            Box::pin(<$shared>::list_tokens(&self.pool))
        }

        fn revoke_token(
            &self,
            id: ::uuid::Uuid,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, bool> {
            Box::pin(<$shared>::revoke_token(&self.pool, id, now_ms))
        }

        fn save_checkpoint(
            &self,
            id: ::uuid::Uuid,
            attempt: i64,
            checkpoint: $crate::store::NewCheckpoint,
            now_ms: i64,
        ) -> $crate::store::StoreFuture<'_, bool> {
            Box::pin(<$shared>::save_checkpoint(
                &self.pool, id, attempt, checkpoint, now_ms,
            ))
        }

        fn load_checkpoint(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Option<$crate::store::JobCheckpoint>> {
            Box::pin(<$shared>::load_checkpoint(&self.pool, id))
        }

        fn save_record_chunk(
            &self,
            id: ::uuid::Uuid,
            attempt: i64,
            seq: u64,
            data: Vec<u8>,
        ) -> $crate::store::StoreFuture<'_, bool> {
            Box::pin(<$shared>::save_record_chunk(
                &self.pool, id, attempt, seq, data,
            ))
        }

        fn load_record_chunks(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Vec<Vec<u8>>> {
            Box::pin(<$shared>::load_record_chunks(&self.pool, id))
        }

        fn job_plan(
            &self,
            id: ::uuid::Uuid,
        ) -> $crate::store::StoreFuture<'_, Option<::serde_json::Value>> {
            Box::pin(<$shared>::job_plan(&self.pool, id))
        }
    };
}
pub(crate) use portable_store_methods;
