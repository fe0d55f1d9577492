// World position from the depth buffer, written the way a Unity project's
// HLSL does it in a full-screen pass: the pixel's clip-space position from
// its texture coordinate and the raw depth, through the inverse
// view-projection matrix, then the divide by w. depthbench runs it as the
// variant `unity_world_position` (see docs/variant-files.md for the
// constants named db_*).
//
// depthbench: input=hardware entry=ComputeWorldPosition uv=top-left view=right-handed

float3 ComputeWorldPosition(float2 uv, float deviceDepth)
{
    // Texture v grows downwards; clip-space y grows upwards.
    float2 ndc = uv * 2.0 - 1.0;
    ndc.y = -ndc.y;
    // A GL-style depth range stores [0, 1] for clip depth [-1, 1].
    float ndcDepth = deviceDepth;
    if ((db_Convention & DB_CONVENTION_CLIP_MINUS_ONE) != 0)
    {
        ndcDepth = deviceDepth * 2.0 - 1.0;
    }
    float4 positionWS = mul(db_InverseViewProjection, float4(ndc, ndcDepth, 1.0));
    return positionWS.xyz / positionWS.w;
}
