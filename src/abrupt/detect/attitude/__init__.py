"""Strike detectors on attitude telemetry: momentum-change statistics (GLR, CUSUM, summation,
Shiryaev) and matched filters on attitude and body rates (Bennett 2022, ch. 2)."""
